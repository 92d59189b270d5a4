"""The link's acknowledged commands (backend/robot/link_acks.py): each written again, the same
message with the same sequence number, every COMMAND_RESEND until the robot acknowledges it, the
link is lost or the bound passes; then an error naming the command, the time and the sends."""

import re

import pytest

from backend.robot.link_acks import COMMAND_RESEND, Acknowledgements, describe
from backend.robot.link_types import LinkError
from backend.robot.messages import Ack, Command, Kind, Leg, Result, SetLeg
from tests.helpers import answer_within

SET_LEG = SetLeg(812, Leg.RIGHT, 35.0, 0.88)
HANG_S = 5.0  # [s] "answers instead of hanging": generous, not a latency claim
BOUND = 4 * COMMAND_RESEND  # [s] a short bound for these tests, on a Ticking clock
TICK = COMMAND_RESEND / 4  # [s] a Ticking clock's step
UNANSWERED = re.compile(r"no acknowledgement for (.+) in ([\d.]+) s after (\d+) sends(.*)")


class Robot:
    """The line and the robot as one writer: it keeps what is written, acknowledges the ``answer_on``-th
    copy (None: never), and the ``blocked`` copies (1-based) fail as on a jammed line."""

    def __init__(self, acks: Acknowledgements, answer_on: int | None = None, blocked: tuple = ()):
        self.acks, self.answer_on, self.blocked = acks, answer_on, blocked
        self.sent: list = []

    def __call__(self, message, deadline: float | None = None) -> None:
        self.sent.append(message)
        if len(self.sent) in self.blocked:
            raise LinkError("write blocked for 100 ms: the line is jammed")
        if len(self.sent) == self.answer_on:
            self.acks.heard(Ack(1, message.seq, Result.OK))


class Ticking:
    """A clock the test controls: each reading is TICK after the one before, however long the thread
    was kept from running in between, so the copies sent before a bound passes do not depend on the
    machine's load. (The waits between readings are real, and short: a fraction of COMMAND_RESEND.)"""

    def __init__(self):
        self.now = 0.0

    def __call__(self) -> float:
        self.now += TICK
        return self.now


def _unanswered(call) -> re.Match:
    def raises():
        with pytest.raises(LinkError) as raised:
            call()
        return str(raised.value)

    message = answer_within(HANG_S, raises)
    match = UNANSWERED.fullmatch(message)
    assert match, message
    return match


def test_a_command_is_named_by_its_kind_body_and_sequence_number():
    assert describe(SET_LEG) == "SET_LEG (right leg, psi0 35.00°, zeta0 0.8800, seq 812)"
    assert describe(Command(5, Kind.RESET)) == "RESET (seq 5)"


def test_a_late_acknowledgement_is_waited_for_and_the_same_message_resent():
    acks = Acknowledgements()
    robot = Robot(acks, answer_on=3)
    ack = answer_within(HANG_S, lambda: acks.send(SET_LEG, robot, bound=10.0))
    assert ack == Ack(1, 812, Result.OK)
    assert robot.sent == [SET_LEG] * 3, "the same message, its sequence number unchanged"
    assert acks.resends == 2


def test_a_command_never_acknowledged_names_itself_its_time_and_its_sends():
    clock = Ticking()
    acks = Acknowledgements(clock=clock)
    robot = Robot(acks)
    match = _unanswered(lambda: acks.send(SET_LEG, robot, bound=BOUND))
    assert match[1] == describe(SET_LEG) and match[4] == "", match[0]
    assert float(match[2]) >= BOUND and clock.now >= BOUND, "it waited out its bound, on the test's clock"
    assert int(match[3]) == len(robot.sent) >= 2 and set(robot.sent) == {SET_LEG}
    assert acks.resends == len(robot.sent) - 1


def test_a_lost_link_ends_the_wait_and_is_named():
    acks = Acknowledgements()
    robot = Robot(acks)
    gone = lambda: "no heartbeat from the robot for 1 s" if len(robot.sent) >= 2 else None  # noqa: E731
    match = _unanswered(lambda: acks.send(Command(9, Kind.DISARM), robot, bound=60.0, gone=gone))
    assert match[1] == "DISARM (seq 9)" and len(robot.sent) == 2, "nothing written once it is lost"
    assert match[4] == ": the link was lost (no heartbeat from the robot for 1 s)", match[0]


def test_a_blocked_write_is_tried_again_and_named_if_nothing_gets_through():
    acks = Acknowledgements()
    robot = Robot(acks, answer_on=3, blocked=(1, 2))
    assert acks.send(SET_LEG, robot, bound=10.0).acked == 812 and len(robot.sent) == 3
    acks = Acknowledgements(clock=Ticking())
    jammed = Robot(acks, blocked=tuple(range(1, 100)))
    match = _unanswered(lambda: acks.send(SET_LEG, jammed, bound=BOUND))
    assert "jammed" in match[4] and f"{len(jammed.sent)} failed" in match[4], match[0]


def test_nothing_is_resent_while_quiet():
    acks = Acknowledgements(clock=Ticking())
    robot = Robot(acks)
    match = _unanswered(lambda: acks.send(Command(4, Kind.RESET), robot, bound=BOUND, quiet=lambda: True))
    assert robot.sent == [Command(4, Kind.RESET)] and match[3] == "1" and acks.resends == 0


def test_an_acknowledgement_is_delivered_to_its_own_command_only():
    acks = Acknowledgements()
    event, box = acks.expect(5)
    acks.heard(Ack(1, 6, Result.OK))
    assert not event.is_set() and box == []
    acks.heard(Ack(2, 5, Result.REJECTED_STATE))
    assert event.is_set() and box == [Ack(2, 5, Result.REJECTED_STATE)]
    acks.forget(5)
    acks.heard(Ack(3, 5, Result.OK))  # late: nobody waits for it any more
    assert box == [Ack(2, 5, Result.REJECTED_STATE)]
