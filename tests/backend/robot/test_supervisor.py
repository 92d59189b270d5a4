"""The link's one owner against a flapping radio: the virtual robot up, gone, silent, or dropping each connection.

The flapping tests check what the supervisor promises by construction: one thread opens, reconnects
and closes the link (never two connects at once, never another thread), the threads come back to
the baseline, and nothing is raised or logged as an error while the radio flaps.
"""

import logging
import threading
import time

import pytest

from backend.robot.link import LinkError, LinkState, RobotLink
from backend.robot.supervisor import LinkSupervisor
from backend.robot.virtual import VirtualRobot
from tests.helpers import answer_within
from tests.robot_rig import LinkCalls, Radio

QUICK_FLAP_S = 4.0  # [s] of flapping in the quick test
SLOW_FLAP_S = 20.0  # [s] of flapping in the slow one
THREADS_SPARE = 3  # threads above the baseline once the flapping ends (pytest's, logging's: not ours)
THREADS_DURING = 8  # at most this many above the baseline while it flaps: supervisor, link, robot, rig
BACK_WITHIN_S = 10.0  # [s] "comes back instead of never": generous, not a latency claim
ANSWER_BOUND_S = 20.0  # [s] a request answers instead of hanging (a bounded connect and closes fit in it)


@pytest.fixture
def thread_errors(monkeypatch):
    """Exceptions that escape any thread (they would print a traceback, not log one)."""
    errors = []
    monkeypatch.setattr(threading, "excepthook", errors.append)
    return errors


def _wait_for(predicate, what: str, timeout: float = BACK_WITHIN_S) -> None:
    deadline = time.monotonic() + timeout
    while not predicate():
        assert time.monotonic() < deadline, f"{what} within {timeout:g} s"
        time.sleep(0.02)


def _flap(seconds: float, monkeypatch, caplog, thread_errors) -> dict:
    """Connect through a supervisor, flap the radio for ``seconds``, end with the robot up; returns what was seen."""
    caplog.set_level(logging.DEBUG, logger="parkourlab.robot")
    calls = LinkCalls(monkeypatch)
    baseline = threading.active_count()
    radio = Radio()
    robot = VirtualRobot("127.0.0.1", radio.port).start()
    supervisor = LinkSupervisor()
    link = RobotLink(radio.url)
    assert answer_within(ANSWER_BOUND_S, supervisor.connect, link) == LinkState.DISARMED
    robot.stop()
    radio.flap(seconds)
    most_threads = baseline
    while radio.flapping:
        most_threads = max(most_threads, threading.active_count())
        time.sleep(0.01)
    radio.join()
    robot = VirtualRobot("127.0.0.1", radio.port).start()  # the robot is back for good
    try:
        _wait_for(lambda: link.state == LinkState.DISARMED, "the link is back once the robot is")
        answer_within(ANSWER_BOUND_S, supervisor.close)
    finally:
        robot.stop()
    _wait_for(lambda: threading.active_count() <= baseline + THREADS_SPARE, "the threads are back to the baseline")
    after = threading.active_count()
    errors = [r for r in caplog.records if r.levelno >= logging.WARNING or r.exc_info]
    assert errors == [] and thread_errors == [], (errors, thread_errors)
    assert calls.most_connecting == 1, "two connects of one link at once"
    assert calls.callers == {"robot-link-supervisor"}, f"only the supervisor opens and closes: {calls.callers}"
    assert most_threads <= baseline + THREADS_DURING, (baseline, most_threads)
    assert supervisor.link is None and link.state == LinkState.DISCONNECTED
    return {"baseline": baseline, "most": most_threads, "after": after, "phases": radio.phases,
            "reconnects": supervisor.reconnects}  # fmt: skip


def test_a_flapping_link_has_one_owner_and_no_leaks(monkeypatch, caplog, thread_errors):
    seen = _flap(QUICK_FLAP_S, monkeypatch, caplog, thread_errors)
    assert seen["reconnects"] >= 1, seen


@pytest.mark.slow
def test_a_link_flapping_for_20_s_has_one_owner_and_no_leaks(monkeypatch, caplog, thread_errors):
    seen = _flap(SLOW_FLAP_S, monkeypatch, caplog, thread_errors)
    assert set(seen["phases"]) == set(Radio.PHASES) and seen["reconnects"] >= 3, seen
    print(f"threads: baseline {seen['baseline']}, at most {seen['most']} while flapping, {seen['after']} after")


def test_a_disconnect_by_hand_stops_the_retries(monkeypatch):
    calls = LinkCalls(monkeypatch)
    robot = VirtualRobot().start()
    supervisor = LinkSupervisor(retry_period=0.1)
    link = RobotLink(robot.url, heartbeat_timeout=0.3)
    try:
        answer_within(ANSWER_BOUND_S, supervisor.connect, link)
        robot.stop()
        _wait_for(lambda: link.state == LinkState.DISCONNECTED, "the link is seen lost")
        answer_within(ANSWER_BOUND_S, supervisor.disconnect)
        tried = calls.connects
        time.sleep(0.5)  # five retry periods
        assert calls.connects == tried and supervisor.link is None
    finally:
        answer_within(ANSWER_BOUND_S, supervisor.close)
    assert "robot-link-supervisor" not in {thread.name for thread in threading.enumerate()}


def test_a_failed_connect_leaves_nothing_and_shutdown_refuses_more():
    supervisor = LinkSupervisor()
    with pytest.raises(LinkError, match="cannot open"):
        supervisor.connect(RobotLink("socket://127.0.0.1:9"), 0.5)  # refused at once
    assert supervisor.link is None
    answer_within(ANSWER_BOUND_S, supervisor.close)
    with pytest.raises(LinkError, match="shutting down"):
        supervisor.connect(RobotLink("socket://127.0.0.1:9"))
    supervisor.disconnect()  # after shutdown: nothing to do, no error
    answer_within(ANSWER_BOUND_S, supervisor.close)  # a second shutdown: nothing to do
