"""The live run's watch on its eyes, on a clock the test controls: a gap past the bound is named
(silent, or frames without the body) on the second look, ended gaps are kept with their length."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from backend.robot.tracker_watch import TRACKER_TIMEOUT_MS, TRACKER_TIMEOUT_RANGE_MS, TrackerWatch

FRAME = 0.01  # [s] the camera's frame period (100 Hz)
POLL = 0.005  # [s] the run loop's


def test_a_steady_stream_is_never_a_gap():
    watch = TrackerWatch(0.1, now=0.0, frames=0)
    for k in range(1, 2000):
        now = k * POLL
        last_pose = math.floor(now / FRAME) * FRAME
        assert watch.look(now, last_pose, int(now / FRAME)) is None
    assert watch.closed(10.0) == []


def test_silence_is_named_on_the_second_look_past_the_bound():
    watch = TrackerWatch(0.1, now=0.0, frames=0)
    assert watch.look(0.05, last_pose=0.05, frames=5) is None
    assert watch.look(0.151, last_pose=0.05, frames=5) is None, "one look past the bound is not enough"
    gap = watch.look(0.156, last_pose=0.05, frames=5)
    assert gap is not None and not gap.body_lost and gap.seconds == pytest.approx(0.106)
    assert gap.reason(0.1) == "tracker silent: no frame for 106 ms (bound 100 ms)"


def test_frames_without_the_body_are_a_lost_body_not_silence():
    watch = TrackerWatch(0.1, now=0.0, frames=0)
    watch.look(0.02, last_pose=0.02, frames=2)
    watch.look(0.13, last_pose=0.02, frames=13)
    gap = watch.look(0.135, last_pose=0.02, frames=14)
    assert gap.body_lost and gap.reason(0.1).startswith("tracker lost the body: frames arrive without it")


def test_a_run_that_never_sees_a_pose_is_blind_from_its_start():
    watch = TrackerWatch(0.1, now=5.0, frames=0)
    assert watch.look(5.101, last_pose=-math.inf, frames=0) is None
    assert watch.look(5.106, last_pose=-math.inf, frames=0).seconds == pytest.approx(0.106)


def test_an_ended_gap_is_kept_with_its_length_and_an_open_one_is_cut_at_the_end():
    watch = TrackerWatch(0.1, now=0.0, frames=0)
    watch.look(0.01, 0.01, 1)
    watch.look(0.3, 0.01, 1)
    watch.look(0.305, 0.01, 1)
    watch.look(0.41, 0.40, 2)  # poses again: the gap ended at the first of them
    assert [round(gap.seconds, 6) for gap in watch.gaps] == [0.39]
    watch.look(0.6, 0.40, 2)
    watch.look(0.61, 0.40, 2)
    closed = watch.closed(0.7)
    assert [round(gap.seconds, 6) for gap in closed] == [0.39, 0.3]
    record = closed[1].to_record(monotonic_now=0.7, unix_now=1000.0)
    assert record == {"time": pytest.approx(999.7), "ms": pytest.approx(300.0), "kind": "silent"}


def test_the_default_bound_is_within_the_range_a_run_may_choose():
    low, high = TRACKER_TIMEOUT_RANGE_MS
    assert low <= TRACKER_TIMEOUT_MS <= high


@settings(max_examples=60, deadline=None)
@given(
    bound_ms=st.floats(TRACKER_TIMEOUT_RANGE_MS[0], TRACKER_TIMEOUT_RANGE_MS[1]),
    gaps=st.lists(st.floats(0.0, 0.6), min_size=1, max_size=6),
    seed=st.integers(0, 2**32 - 1),
)
def test_the_watch_names_exactly_the_gaps_past_its_bound(bound_ms, gaps, seed):
    """Poses at 100 Hz with random drops, broken by silences of random lengths: the watch, looked at
    every poll, reports a gap iff a silence outlasted the bound by more than a poll, and each gap it
    keeps is a silence that happened, measured from the pose before it to the pose after it."""
    bound = bound_ms / 1000.0
    rng = np.random.default_rng(seed)
    arrivals, t = [], 0.0
    for silence in gaps:  # a stretch of frames, then a silence
        for _ in range(20):
            t += FRAME
            if rng.random() > 0.02:
                arrivals.append(t)
        t += silence
    arrivals.append(t + FRAME)
    watch = TrackerWatch(bound, now=0.0, frames=0)
    index, now = 0, 0.0
    while now < arrivals[-1] + POLL:
        now += POLL
        while index < len(arrivals) and arrivals[index] <= now:
            index += 1
        watch.look(now, arrivals[index - 1] if index else -math.inf, index)
    intervals = np.diff([0.0, *arrivals])
    expected = [gap for gap in intervals if gap > bound + 2 * POLL]
    possible = [gap for gap in intervals if gap > bound]
    kept = [gap.seconds for gap in watch.gaps]
    assert len(expected) <= len(kept) <= len(possible), (kept, expected, possible)
    for length in kept:
        assert np.min(np.abs(intervals - length)) < 1e-9, "a kept gap is a silence that happened"
    assert all(not gap.body_lost for gap in watch.gaps)


def test_datagrams_waiting_unread_are_this_pc_behind_not_the_tracker_silent():
    """A loaded machine holds up the receiving thread: not named while datagrams wait, up to twice the bound."""
    watch = TrackerWatch(0.1, now=0.0, frames=0)
    watch.look(0.01, 0.01, 1)
    for now in (0.12, 0.15, 0.2):
        assert watch.look(now, 0.01, 1, waiting=True) is None
    watch.look(0.215, 0.01, 1, waiting=True)
    assert watch.look(0.22, 0.01, 1, waiting=True) is not None, "past twice the bound, behind is blind"
