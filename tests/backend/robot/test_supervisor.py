"""The link's one owner against a flapping radio: the virtual robot up, gone, silent, or dropping each connection.

The flapping tests check what the supervisor promises by construction: one thread opens, reconnects
and closes the link (never two connects at once, never another thread), the threads come back to
the baseline, and nothing is raised or logged as an error while the radio flaps.
"""

import threading
import time

import pytest

from backend.robot.link import LinkError, LinkState, RobotLink
from backend.robot.supervisor import LinkSupervisor
from backend.robot.virtual import VirtualRobot
from tests.helpers import answer_within
from tests.robot_rig import ANSWER_BOUND_S, LinkCalls, Radio, flap_supervised, wait_for

QUICK_FLAP_S = 4.0  # [s] of flapping in the quick test
SLOW_FLAP_S = 20.0  # [s] of flapping in the slow one (tests/backend/robot/test_faults.py flaps for 2 min)


def test_a_flapping_link_has_one_owner_and_no_leaks(monkeypatch, caplog, thread_errors):
    seen = flap_supervised(QUICK_FLAP_S, monkeypatch, caplog, thread_errors)
    assert seen["reconnects"] >= 1, seen


@pytest.mark.slow
def test_a_link_flapping_for_20_s_has_one_owner_and_no_leaks(monkeypatch, caplog, thread_errors):
    seen = flap_supervised(SLOW_FLAP_S, monkeypatch, caplog, thread_errors)
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
        wait_for(lambda: link.state == LinkState.DISCONNECTED, "the link is seen lost")
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
