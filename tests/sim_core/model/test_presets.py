"""The named presets: the paper's parameters, its gaits and the usual first guess."""

import dataclasses

import pytest

from sim_core import PAPER_GAITS, START_GUESS, ControlSchedule, ParameterError, gait_of, get_preset
from sim_core.model.presets import preset_model


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


def test_a_presets_model_takes_the_overrides_given_and_names_the_field_of_an_unknown_preset():
    paper = get_preset("paper").to_model()
    assert preset_model("paper") == paper
    assert preset_model("paper", alpha=40.0, mu=None) == dataclasses.replace(paper, alpha=40.0)
    with pytest.raises(ParameterError) as unknown:
        preset_model("gone", field="model.preset")
    assert unknown.value.field == "model.preset" and "paper" in unknown.value.message
    with pytest.raises(ParameterError) as bad:
        preset_model("paper", alpha=-1.0)
    assert bad.value.field == "alpha"
