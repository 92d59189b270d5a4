"""A tracker source's frame counts (backend/robot/tracker_stats.py): frame numbers that jump, go back
or arrive late, one run's figures, and malformed packets counted once."""

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from backend.robot.tracker_stats import FRAME_JUMP, LATE_FRAMES, TrackerCounts, TrackerStats


def _counted(numbers) -> TrackerStats:
    stats = TrackerStats()
    for number in numbers:
        stats.frame(number)
    return stats


def test_a_huge_jump_in_frame_numbers_is_a_restart_not_loss():
    stats = _counted([*range(1, 51), 2_000_000_000, 2_000_000_001, 2_000_000_003])
    assert (stats.received, stats.dropped, stats.restarts) == (53, 1, 1), "the gap after the jump still counts"
    assert stats.loss == pytest.approx(1 / 54)


def test_the_longest_gap_counted_as_loss():
    assert _counted([10, 11 + FRAME_JUMP]).snapshot() == TrackerCounts(received=2, dropped=FRAME_JUMP)
    assert _counted([10, 12 + FRAME_JUMP]).snapshot() == TrackerCounts(received=2, restarts=1)


def test_numbers_going_back_are_a_restart_and_gaps_count_again_after_it():
    """The camera software restarted: its numbering begins again, and its gaps are losses again."""
    stats = _counted([*range(5000, 5100), 1, 2, 5, 6])
    assert (stats.received, stats.dropped, stats.restarts) == (104, 2, 1)
    assert stats.last_frame == 6


def test_a_late_frame_is_not_a_restart():
    stats = _counted([1, 2, 4, 3, 5, 5 - LATE_FRAMES, 6])
    assert (stats.received, stats.dropped, stats.restarts) == (7, 1, 0)


def test_counts_over_a_run_are_the_difference_of_two_snapshots():
    stats = _counted([101, 102, 105])
    stats.malformed, stats.ignored = 3, 1
    before = stats.snapshot()
    for number in (106, 109, 110, 1):  # 107 and 108 lost, then a restart
        stats.frame(number)
    stats.malformed += 2
    run = stats.snapshot().since(before)
    assert run == TrackerCounts(received=4, dropped=2, malformed=2, ignored=0, restarts=1)
    assert run.loss == pytest.approx(2 / 6)
    assert before == TrackerCounts(received=3, dropped=2, malformed=3, ignored=1), "a snapshot does not move"
    assert stats.loss == stats.snapshot().loss == pytest.approx(4 / 11)
    assert TrackerCounts().loss == 0.0


@settings(max_examples=300, deadline=None)
@given(st.lists(st.sampled_from(("ok", "malformed", "lost")), max_size=60), st.integers(0, 2**32 - 61))
def test_a_malformed_frame_is_counted_once_never_also_as_dropped(fates, first):
    """Frames numbered ``first`` on: each arrives, arrives malformed (counted as both sources count one)
    or is lost. Dropped: only the lost ones between the first and last frame received."""
    stats = TrackerStats()
    for number, fate in enumerate(fates, first):
        if fate == "ok":
            stats.frame(number)
        elif fate == "malformed":
            stats.malformed += 1
    received = [k for k, fate in enumerate(fates) if fate == "ok"]
    lost = fates[received[0] : received[-1]].count("lost") if received else 0
    assert (stats.received, stats.malformed, stats.dropped, stats.restarts) == (
        len(received),
        fates.count("malformed"),
        lost,
        0,
    )
