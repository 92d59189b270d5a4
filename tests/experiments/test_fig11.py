"""Paper Fig. 11 (experiments/fig11.py): Mean Jumps To Failure over zeta0 with noise — a few
trials per level as on the robot, and a converged estimate from an independent seed stream.

Three levels, a handful of trials and a low cap keep it quick; the full configuration's claims are
checked by tests/experiments/test_reproduce.py (slow).
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from experiments import fig11
from experiments.manifest import json_safe
from sim_core import get_preset
from sim_core.robustness.mjtf import CAPPED

ROBOT = get_preset("paper")
CONFIG = fig11.Config(levels=3, trials=3, converged_trials=8, cap=60)


@pytest.fixture(scope="module")
def result():
    return fig11.run(ROBOT, CONFIG)


def test_the_two_estimates_share_the_levels_and_take_their_own_seeds(result):
    few, many = result.paper_like, result.converged
    assert (few.trials, many.trials) == (CONFIG.trials, CONFIG.converged_trials)
    assert (few.seed, many.seed) == (CONFIG.seed, CONFIG.seed + 1), "the converged estimate reuses no trial"
    assert [level.zeta0 for level in few.levels] == [level.zeta0 for level in many.levels]
    np.testing.assert_allclose([level.zeta0 for level in many.levels], np.linspace(*CONFIG.zeta0_range, 3))


def test_a_seeded_run_is_repeatable(result):
    again = fig11.run(ROBOT, CONFIG)
    for name, column in fig11.table(result).items():
        np.testing.assert_array_equal(fig11.table(again)[name], column, err_msg=name)


def test_every_trial_ends_at_a_failure_or_the_cap(result):
    for level in result.converged.levels:
        assert sum(level.histogram().values()) == CONFIG.converged_trials
        assert np.all(level.jumps <= CONFIG.cap)
        assert np.count_nonzero(level.jumps == CONFIG.cap) >= level.histogram()[CAPPED]
        low, high = level.ci95
        assert low <= level.mean <= high


def test_its_table_has_a_row_per_level_and_counts_the_capped_trials(result):
    table = fig11.table(result)
    assert {len(column) for column in table.values()} == {CONFIG.levels}
    assert np.all(np.diff(table["energy_mgl0"]) < 0), "more zeta0, less energy stored"
    capped = int(table["capped_trials"].sum())
    total = CONFIG.converged_trials * CONFIG.levels
    assert f"{capped} of {total} converged-estimate trials did" in fig11.notes(result)[1]
    data = json.loads(json.dumps(json_safe(fig11.data(result)), allow_nan=False))
    assert data["converged"]["seed"] == CONFIG.seed + 1


def test_the_failure_summary_shares_out_the_failures(result):
    summary = fig11.claims(result)[2].ours.removeprefix("failures here are ")
    failures = {}
    for level in result.converged.levels:
        for code, count in level.histogram().items():
            if code != CAPPED and count:
                failures[code] = failures.get(code, 0) + count
    parts = dict(part.split(" ") for part in summary.split(", ")) if summary else {}
    assert set(parts) == set(failures), "each failure that happened, and only those"
    assert sum(int(share.rstrip("%")) for share in parts.values()) == pytest.approx(100, abs=len(parts))


def test_the_figure_stacks_how_trials_ended_to_one_per_level(result):
    figure = fig11.plot(result)
    try:
        ends = figure.axes[1]
        assert ends.get_title() == f"How trials ended (cap {CONFIG.cap} jumps)"
        levels: dict[float, list] = {}
        for bar in ends.patches:
            levels.setdefault(round(bar.get_x() + 0.5 * bar.get_width(), 9), []).append(bar)
        assert len(levels) == CONFIG.levels
        for zeta0, bars in levels.items():
            bars.sort(key=lambda bar: bar.get_y())
            tops = np.cumsum([bar.get_height() for bar in bars])
            np.testing.assert_allclose([bar.get_y() for bar in bars], np.r_[0.0, tops[:-1]], err_msg=f"{zeta0}")
            assert tops[-1] == pytest.approx(1.0), f"every trial at zeta0 = {zeta0} ended one way"
    finally:
        figure.clf()
