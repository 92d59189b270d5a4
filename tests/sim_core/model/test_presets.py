"""The named presets: the paper's parameters, its gaits and the usual first guess."""

import pytest

from sim_core import PAPER_GAITS, START_GUESS, ControlSchedule, ParameterError, gait_of, get_preset


@pytest.mark.parametrize(("name", "period"), [("period 1", 1), ("period 2", 2), ("period 4", 4)])
def test_paper_gaits_are_stable_gaits_of_their_period(paper, name, period):
    schedule = ControlSchedule.from_degrees(PAPER_GAITS[name])
    gait = gait_of(paper, schedule, period, START_GUESS, prefer_stable=True)
    assert gait.period == period, f"{name}: minimal period"
    assert gait.stable and gait.motion == "climbing", f"{name}: max |λ| {gait.max_abs_eigenvalue:.3f}"


def test_start_guess_leads_levenberg_marquardt_to_the_period1_gait(paper):
    gait = gait_of(paper, ControlSchedule.from_degrees(PAPER_GAITS["period 1"]), guess=START_GUESS)
    assert gait.period == 1 and gait.stable


def test_paper_gaits_are_the_papers_controls():
    assert dict(PAPER_GAITS) == {
        "period 1": ((30.0, 0.9),),
        "period 2": ((30.0, 0.87), (30.0, 0.9)),
        "period 4": ((30.0, 0.9), (35.0, 0.9505)),
    }
    with pytest.raises(TypeError):
        PAPER_GAITS["period 3"] = ((30.0, 0.9),)  # read-only: every caller sees the same gaits


def test_unknown_preset_names_the_known_ones():
    with pytest.raises(ParameterError, match="known presets: paper"):
        get_preset("moon")
