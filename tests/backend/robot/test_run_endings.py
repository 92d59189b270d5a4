"""A live run's end reasons: what the robot's state and faults say, named; falls read back."""

import pytest

from backend.robot.link_types import LinkError, LinkState
from backend.robot.messages import Fault
from backend.robot.run_endings import CLEAN_ENDINGS, end_safely, fault_names, fell, robot_ending, robot_ending_record

RESTART = "robot restarted (brown-out; its sequence went back from 42 to 2)"  # as the link words it


@pytest.mark.parametrize(
    ("state", "faults", "restart", "says"),
    [
        (LinkState.DISCONNECTED, 0, None, "link lost"),
        (LinkState.ESTOPPED, Fault.FELL, None, "e-stop"),
        (LinkState.DISARMED, Fault.FELL, None, "fell: the robot reported a fall (FELL) after touchdown 7"),
        (LinkState.DISARMED, Fault.FELL | Fault.BROWNOUT, RESTART, "robot restarted: brown-out; its sequence"),
        (LinkState.DISARMED, Fault.HEARTBEAT_LOST, None, "robot disarmed itself: it heard no heartbeat"),
        (LinkState.DISARMED, 0, None, "robot disarmed itself: it reports disarmed, with no fault"),
        (LinkState.ARMED, Fault.LOW_BATTERY, None, "robot disarmed itself: it reports armed, with no fault"),
    ],
)
def test_the_robots_own_ending_is_named(state, faults, restart, says):
    reason = robot_ending(state, int(faults), restart, touchdowns=7)
    assert reason.startswith(says) and reason not in CLEAN_ENDINGS


def test_fault_names_read_every_bit():
    assert fault_names(int(Fault.FELL | Fault.HEARTBEAT_LOST)) == ["heartbeat_lost", "fell"]
    assert fault_names(0) == []


@pytest.mark.parametrize(
    ("reason", "faults", "expected"),
    [
        ("fell: the robot reported a fall (FELL) after touchdown 3", [], True),
        ("jumps done", ["fell"], True),
        ("robot disarmed (fell or timed out)", None, True),  # stored before the endings were named
        ("tracker silent: no frame for 120 ms (bound 100 ms)", ["heartbeat_lost"], False),
        ("jumps done", None, False),
        (None, None, False),
    ],
)
def test_a_stored_fall_is_read_back(reason, faults, expected):
    assert fell(reason, faults) is expected


class _Link:
    def __init__(self, answer):
        self.answer = answer

    def make_safe(self):
        if isinstance(self.answer, Exception):
            raise self.answer
        return self.answer


def test_every_ending_says_how_it_left_the_robot():
    assert end_safely(_Link(LinkState.DISARMED)) == "disarmed"
    assert end_safely(_Link(LinkError("the link is down"))) == "not confirmed: the link is down"


def test_a_runs_fall_record_reads_its_ending_its_faults_and_its_telemetry():
    """One record for a stored run and for one stored before it (calibrations.run_fell reads both)."""
    assert robot_ending_record("jumps done", (), [{"faults": 0}]) == {"robot_faults": [], "fell": False}
    assert robot_ending_record("jumps done", (), [{"faults": int(Fault.FELL)}])["fell"] is True
    assert robot_ending_record("robot disarmed (fell or timed out)", (), []) == {"robot_faults": [], "fell": True}
    record = robot_ending_record("e-stop", ("booted",), [{"faults": int(Fault.HEARTBEAT_LOST)}])
    assert record == {"robot_faults": ["booted", "heartbeat_lost"], "fell": False}
