"""Paper Fig. 7 (experiments/fig7.py): the stable gaits of period 1, 2 and 4, the zeta0_R scan
that finds the period-4 one, and the claim that period 4 begins where period 2 doubles.

A short scan (8 values in the period-4 side of the range, short transients) keeps it quick; the
full configuration's claims are checked by tests/experiments/test_reproduce.py (slow).
"""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest

from experiments import fig7
from experiments.manifest import json_safe
from sim_core import get_preset
from sim_core.model.errors import FixedPointNotFound

ROBOT = get_preset("paper")
CONFIG = fig7.Config(zeta0_right_range=(0.93, 0.965), scan_steps=8, transient_jumps=200, kept_jumps=32)


@pytest.fixture(scope="module")
def result():
    return fig7.run(ROBOT, CONFIG)


def test_the_gaits_have_periods_one_two_and_four_and_are_stable(result):
    assert [gait.period for gait in result.gaits] == [1, 2, 4]
    assert all(gait.stable for gait in result.gaits)
    assert [claim.agrees for claim in fig7.claims(result)[:3]] == [True, True, True]


def test_the_period_four_gait_is_taken_from_the_middle_of_its_band(result):
    band = result.scan_zeta0[result.scan_period == 4]
    assert band.size >= 3, result.scan_period
    assert result.zeta0_right == band[band.size // 2]
    right_leg = result.schedules[2][1]
    assert right_leg.zeta0 == result.zeta0_right and right_leg.psi0_deg == pytest.approx(35.0)


def test_each_path_runs_two_periods_from_its_fixed_point(result):
    for gait, path in zip(result.gaits, result.paths, strict=True):
        assert len(path.touchdown_times) == 2 * gait.period + 1, f"period {gait.period}: touchdowns 0 … 2p"
        assert path.time[0] == 0.0


def test_a_range_without_a_period_four_attractor_says_so():
    config = dataclasses.replace(CONFIG, zeta0_right_range=(0.90, 0.91), scan_steps=3, transient_jumps=100)
    with pytest.raises(FixedPointNotFound, match="no period-4 attractor"):
        fig7.run(ROBOT, config)


def test_period_four_must_begin_just_after_the_doubling(result):
    """The fourth claim, on a hand-made scan: period 2's eigenvalue crosses -1 at zeta0_R = 0.918."""
    zeta0 = np.array([0.90, 0.91, 0.92, 0.93])
    eigenvalues = np.array([[-0.8, 0.1], [-0.92, 0.1], [-1.02, 0.1], [-1.2, 0.1]], dtype=complex)
    scan = dataclasses.replace(result, scan_zeta0=zeta0, period2_eigenvalues=eigenvalues)
    just_after = fig7.claims(dataclasses.replace(scan, scan_period=np.array([2, 2, 4, 4])))[3]
    assert "crosses -1 at zeta0_R ≈ 0.9180" in just_after.ours and "+0.0020 after it" in just_after.ours
    assert just_after.agrees is True
    before = fig7.claims(dataclasses.replace(scan, scan_period=np.array([4, 4, 4, 4])))[3]
    assert before.agrees is False, "a band starting a step before the crossing is not the doubling"
    stays_stable = eigenvalues.real * 0.5 + 0j  # never reaches -1
    never = fig7.claims(dataclasses.replace(scan, period2_eigenvalues=stays_stable, scan_period=np.array([2, 2, 4, 4])))
    assert never[3].agrees is False and "not in range" in never[3].ours


def test_its_table_and_data_are_one_row_per_scanned_zeta0(result):
    table = fig7.table(result)
    assert {len(column) for column in table.values()} == {CONFIG.scan_steps}
    np.testing.assert_array_equal(table["attractor_period_jumps"], result.scan_period)
    data = json.loads(json.dumps(json_safe(fig7.data(result)), allow_nan=False))
    assert data["period4_zeta0_right"] == result.zeta0_right
    assert [gait["period"] for gait in data["gaits"]] == [1, 2, 4]
    assert len(data["scan"]["attractor_ydot"]) == CONFIG.scan_steps


def test_the_figure_has_a_column_per_gait_and_the_scan(result):
    figure = fig7.plot(result)
    try:
        titles = [ax.get_title() for ax in figure.axes]
        assert sum(title.startswith("Period ") for title in titles) == 3
        assert "Bifurcation diagram (attractor)" in titles
    finally:
        figure.clf()
    assert f"{CONFIG.scan_steps} values" in fig7.notes(result)[0]
