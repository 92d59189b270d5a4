"""Tracker input (backend/robot/tracker.py): PKT1 datagrams, the UDP pose source and its counts, recorded
replays, and frame numbers that jump, go back or arrive late."""

import math
import socket
import time

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from backend.robot.tracker import (
    FRAME_JUMP,
    LATE_FRAMES,
    Calibration,
    Pose,
    TrackerCounts,
    TrackerStats,
    UdpPoseSource,
    decode_datagram,
    encode_datagram,
    recorded_poses,
)


def test_datagrams_round_trip_and_reject_garbage():
    pose = Pose(12.5, -0.1, 0.42, math.nan)
    frame, back = decode_datagram(encode_datagram(7, pose))
    assert frame == 7 and back.time == 12.5 and back.y == 0.42 and math.isnan(back.pitch)
    for bad in (b"", b"x" * 40, encode_datagram(1, pose)[:-1]):
        with pytest.raises(ValueError):
            decode_datagram(bad)


def test_udp_source_counts_drops_and_goes_stale():
    source = UdpPoseSource(calibration=Calibration(origin=(1.0, 0.0)), stale_after=0.2)
    sender = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    try:
        now = time.time()
        for frame in (1, 2, 5, 6):  # frames 3 and 4 lost
            sender.sendto(encode_datagram(frame, Pose(now, 1.25, 0.5)), source.address)
        sender.sendto(b"garbage", source.address)
        deadline = time.monotonic() + 2
        while source.stats.received + source.stats.malformed < 5 and time.monotonic() < deadline:
            time.sleep(0.01)
        assert (source.stats.received, source.stats.dropped, source.stats.malformed) == (4, 2, 1)
        assert source.stats.loss == pytest.approx(2 / 6)
        assert (source.protocol, source.version, source.error) == ("pkt1", "1", None)
        latest = source.latest()
        assert latest is not None and latest.x == pytest.approx(0.25), "calibrated to wall coordinates"
        assert source.latest(time.monotonic() + 1.0) is None, "stale: nothing arrived for a second"
    finally:
        sender.close()
        source.close()


def test_recorded_poses_replay(climb):
    _robot, _schedule, _path, si = climb
    history = recorded_poses({"time": si.time, "x": si.x, "y": si.y})
    assert len(history.poses_since(si.time[-10])) == 10
    assert history.as_arrays()["y"][-1] == si.y[-1]


def test_indices_count_every_pose_received_when_old_ones_are_let_go(monkeypatch):
    from backend.robot import tracker

    monkeypatch.setattr(tracker, "HISTORY", 5)
    history = tracker.PoseHistory(Calibration())
    for k in range(12):
        history.add(Pose(float(k), 0.0, 0.0, 0.0))
    assert history.count() == 12, "a live run's index keeps counting past the history kept"
    assert [pose.time for pose in history.poses_from(9)] == [9.0, 10.0, 11.0]
    assert [pose.time for pose in history.poses_from(0)] == [7.0, 8.0, 9.0, 10.0, 11.0], "from the oldest kept"


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
