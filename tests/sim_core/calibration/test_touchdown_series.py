"""Tracked touchdowns as calibration reads them (sim_core.calibration.touchdown_series): which pairs count, what
a fall leaves out, the pairs' tables, the pitch at a touchdown and its drift."""

import math

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

from sim_core.calibration.touchdown_series import (
    COLUMNS,
    FALL_PAIRS,
    PITCH_WINDOW,
    PSI0_ERROR,
    ZETA0_ERROR,
    Pairs,
    TouchdownSeries,
    finite_rms,
    pitch_at,
    pitch_drift_deg,
)
from sim_core.model.validation import ParameterError

LEG = (math.radians(30.0), 0.9)


def _series(right_leg, *, fell=False, pitch=None) -> TouchdownSeries:
    n = len(right_leg)
    return TouchdownSeries.of(
        state=[(-0.9 - 0.01 * k, -0.2 + 0.01 * k) for k in range(n)],
        foot_height=[0.1 * k for k in range(n)],
        commanded=[LEG] * n,
        right_leg=right_leg,
        pitch=pitch,
        fell=fell,
    )


def test_a_pair_counts_when_the_walls_alternate():
    run = _series([False, True, False, False, True])  # a touchdown missed between 2 and 3
    assert_array_equal(run.consecutive, [True, True, False, True])
    assert run.pairs == 3
    assert_array_equal(run.steady, run.consecutive, err_msg="a run that did not fall keeps every pair")


def test_a_fall_leaves_out_its_last_pairs():
    run = _series([False, True, False, True], fell=True)
    assert_array_equal(run.steady, [True] * (3 - FALL_PAIRS) + [False] * FALL_PAIRS)
    assert not _series([False], fell=True).steady.size, "one touchdown: no pair to leave out"


def test_a_missing_pitch_is_zero():
    run = _series([False, True, False], pitch=[0.01, math.nan, -0.02])
    assert_array_equal(run.pitch, [0.01, 0.0, -0.02])
    assert_array_equal(_series([False, True]).pitch, [0.0, 0.0])


def test_columns_of_the_wrong_shape_name_the_field():
    run = _series([False, True, False])
    with pytest.raises(ParameterError, match=r"^foot_height: must have shape \(3,\), got \(2,\)$"):
        TouchdownSeries(run.state, run.foot_height[:2], run.commanded, run.right_leg, run.pitch, run.consecutive)


def test_pairs_are_rows_k_and_k_plus_one_of_every_run():
    first = _series([False, True, False, False, True])
    second = _series([True, False], pitch=[0.03, 0.04])
    pairs = Pairs.of([first, second])
    assert len(pairs) == 4 and pairs.before.shape == pairs.after.shape == (4, COLUMNS)
    assert_array_equal(pairs.origin, [[0, 1], [0, 2], [0, 4], [1, 1]])
    for (position, k), before, after in zip(pairs.origin, pairs.before, pairs.after, strict=True):
        run = (first, second)[position]
        assert_array_equal(before[:2], run.state[k - 1])
        assert_array_equal(after[:2], run.state[k])
        assert after[5] == run.right_leg[k] and after[6] == run.pitch[k]
    assert_array_equal(pairs.before[:, [PSI0_ERROR, ZETA0_ERROR]], 0.0, err_msg="as measured: no control error")
    assert_allclose(pairs.before[:, 3:5], np.tile(LEG, (4, 1)))


def test_measured_is_the_next_state_and_the_feet_rise():
    pairs = Pairs.of([_series([False, True, False])])
    assert_allclose(pairs.measured(), [[-0.91, -0.19, 0.1], [-0.92, -0.18, 0.1]])


def test_steady_pairs_leave_out_a_fall_and_no_runs_give_no_pairs():
    fell = _series([False, True, False, True], fell=True)
    assert len(Pairs.of([fell], steady=True)) == len(Pairs.of([fell])) - FALL_PAIRS
    empty = Pairs.of([])
    assert len(empty) == 0 and empty.before.shape == (0, COLUMNS) and empty.origin.shape == (0, 2)


def test_the_pitch_at_a_touchdown_is_the_median_just_before_it():
    frame_time = np.arange(0.0, 1.0, 0.01)
    frame_pitch = np.where(frame_time < 0.5, 0.1, 0.3)
    frame_pitch[45] = math.nan  # a frame without pitch is skipped
    frame_pitch[47] = 5.0  # one wild frame does not move the median
    pitch = pitch_at([0.5, 0.9, 2.0], frame_time, frame_pitch)
    assert pitch[0] == pytest.approx(0.1), f"frames in {PITCH_WINDOW} s before the touchdown: before the step"
    assert pitch[1] == pytest.approx(0.3)
    assert pitch[2] == 0.0, "no frames: 0"


def test_the_drift_is_the_spread_of_the_pitch_steps_between_consecutive_touchdowns():
    steps = [0.01, -0.02, 0.015]
    pitch = np.concatenate([[0.0], np.cumsum(steps)])
    run = _series([False, True, False, True], pitch=pitch)
    assert pitch_drift_deg([run]) == pytest.approx(math.degrees(np.std(steps, ddof=1)))
    broken = _series([False, True, True, False], pitch=pitch)  # the step between 1 and 2 is no jump
    assert pitch_drift_deg([broken]) == pytest.approx(math.degrees(np.std([0.01, 0.015], ddof=1)))
    assert pitch_drift_deg([_series([False, True, False])]) == 0.0, "no tracked pitch: no drift"


def test_finite_rms_skips_failed_predictions():
    values = np.array([[3.0, math.nan], [4.0, math.nan], [math.inf, math.nan]])
    assert finite_rms(values) == pytest.approx(math.sqrt(12.5))
    by_column = finite_rms(values, axis=0)
    assert by_column[0] == pytest.approx(math.sqrt(12.5)) and math.isnan(by_column[1])
