"""Tracker input (backend/robot/tracker.py): PKT1 datagrams, the UDP pose source and its counts, recorded
replays, and what a live run's watch reads of it (arrivals, datagrams waiting). The counts
themselves: test_tracker_stats.py."""

import math
import socket
import time

import pytest

from backend.robot.tracker import (
    Calibration,
    Pose,
    UdpPoseSource,
    decode_datagram,
    encode_datagram,
    recorded_poses,
)

STALE_S = 0.2  # [s] the source's stale_after here
WAIT_S = 10.0  # [s] for datagrams sent on localhost to be read: a hang guard


def test_datagrams_round_trip_and_reject_garbage():
    pose = Pose(12.5, -0.1, 0.42, math.nan)
    frame, back = decode_datagram(encode_datagram(7, pose))
    assert frame == 7 and back.time == 12.5 and back.y == 0.42 and math.isnan(back.pitch)
    for bad in (b"", b"x" * 40, encode_datagram(1, pose)[:-1]):
        with pytest.raises(ValueError):
            decode_datagram(bad)


def test_udp_source_counts_drops_and_goes_stale():
    source = UdpPoseSource(calibration=Calibration(origin=(1.0, 0.0)), stale_after=STALE_S)
    sender = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    try:
        now = time.time()
        for frame in (1, 2, 5, 6):  # frames 3 and 4 lost
            sender.sendto(encode_datagram(frame, Pose(now, 1.25, 0.5)), source.address)
        sender.sendto(b"garbage", source.address)
        deadline = time.monotonic() + WAIT_S
        while source.stats.received + source.stats.malformed < 5 and time.monotonic() < deadline:
            time.sleep(0.01)
        assert (source.stats.received, source.stats.dropped, source.stats.malformed) == (4, 2, 1)
        assert source.stats.loss == pytest.approx(2 / 6)
        assert (source.protocol, source.version, source.error) == ("pkt1", "1", None)
        # Asked on the clock the test gives (when the last arrived, and after): not on this machine's.
        arrived = source.arrived()
        latest = source.latest(arrived + 0.9 * STALE_S)
        assert latest is not None and latest.x == pytest.approx(0.25), "calibrated to wall coordinates"
        assert source.latest(arrived + 1.1 * STALE_S) is None, "stale: nothing arrived for longer than stale_after"
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


def test_the_newest_time_is_the_newest_pose_s_once_a_run_s_first_has_arrived(monkeypatch):
    """A live run's stamp on its commands and telemetry: the tracker's time, never before its own frames."""
    from backend.robot import tracker

    monkeypatch.setattr(tracker, "HISTORY", 5)
    history = tracker.PoseHistory(Calibration())
    assert history.newest_time() is None, "no pose yet"
    for k in range(3):
        history.add(Pose(100.0 + 0.01 * k, 0.0, 0.0))
    first_pose = history.count()  # a run starts here: the poses before it are not its own
    assert history.newest_time() == 100.02 and history.newest_time(first_pose) is None
    for k in range(3, 12):
        history.add(Pose(100.0 + 0.01 * k, 0.0, 0.0))
    assert history.newest_time(first_pose) == 100.11, "the newest, past the history kept"
    assert history.newest_time(12) is None


def test_a_source_says_when_its_last_pose_arrived_and_whether_datagrams_wait_unread():
    source = UdpPoseSource()
    try:
        assert source.arrived() == -math.inf and not source.waiting()
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sender:
            sender.sendto(encode_datagram(1, Pose(0.0, 0.0, 0.5)), source.address)
            deadline = time.monotonic() + 5
            while source.count() == 0:
                assert time.monotonic() < deadline, "the pose within 5 s"
                time.sleep(0.001)
            assert time.monotonic() - source.arrived() < 5 and not source.waiting()
            source._stop.set()  # the receiving thread held up: what arrives now waits in the socket
            source._thread.join(2)
            sender.sendto(encode_datagram(2, Pose(0.01, 0.0, 0.5)), source.address)
            deadline = time.monotonic() + 5
            while not source.waiting():
                assert time.monotonic() < deadline, "the datagram waits within 5 s"
                time.sleep(0.001)
    finally:
        source.close()
    assert not source.waiting(), "a closed source has nothing waiting"
