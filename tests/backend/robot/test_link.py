"""The PC's link against the virtual robot over a real TCP socket (pyserial ``socket://``)."""

import itertools
import re
import socket
import time

import pytest

from backend.robot.firmware import Firmware
from backend.robot.link import WRITE_TIMEOUT, EstopLatched, LinkError, LinkState, RobotLink
from backend.robot.link_cadence import HEARTBEAT_PERIOD
from backend.robot.messages import Ack, Fault, Kind, Leg, RobotState, SetLeg
from backend.robot.virtual import VirtualRobot
from sim_core import ParameterError
from tests.helpers import answer_within
from tests.robot_rig import FOREIGN, PtyRobot, received_frame, telemetry

NETWORK_ACK_FAILURE = 0x21  # a Transmit Status: the robot's radio did not acknowledge the frame
ADDRESS_NOT_FOUND = 0x24
JAMMED_ANSWER_S = 2.0  # [s] "answers instead of hanging": a generous bound, not a latency claim
# [s] the same for a command, which tries again for its whole bound (the heartbeat timeout and a margin)
COMMAND_ANSWER_S = 6.0
# [s] the link's heartbeat timeout where a test needs the link to stay up: a hang guard, 50 of the
# robot's telemetry periods, so a loaded machine that keeps the robot's thread from running for a
# while is no lost link. A test of a lost link keeps a short one: there, a loss is what it waits for.
PATIENT_LINK_S = 5.0
WAIT_S = 10.0  # [s] _wait_for's bound: a hang guard, not a latency claim


@pytest.fixture
def robot():
    virtual = VirtualRobot().start()
    yield virtual
    virtual.stop()


@pytest.fixture
def link(robot):
    connection = RobotLink(robot.url, heartbeat_timeout=PATIENT_LINK_S)
    connection.connect()
    yield connection
    connection.close()


def _wait_for(predicate, timeout=WAIT_S):
    deadline = time.monotonic() + timeout
    while not predicate():
        assert time.monotonic() < deadline, "timed out"
        time.sleep(0.01)


def test_connect_arm_command_disarm(robot, link):
    assert link.state == LinkState.DISARMED
    link.arm()
    _wait_for(lambda: link.state == LinkState.ARMED)
    link.set_leg(Leg.RIGHT, 35.0, 0.88)
    assert robot.firmware.legs[Leg.RIGHT] == (35.0, 0.88)
    _wait_for(lambda: link.telemetry.psi_servo_deg[1] == 35.0)
    link.disarm()
    _wait_for(lambda: link.state == LinkState.DISARMED)
    assert [t.after for t in link.transitions] == [LinkState.DISARMED, LinkState.ARMED, LinkState.DISARMED]


def test_commands_beyond_servo_limits_are_refused_before_sending(robot, link):
    with pytest.raises(ParameterError, match=r"^zeta0: must be in \[0.75, 0.98\]"):
        link.set_leg(Leg.LEFT, 30.0, 0.99)
    assert robot.firmware.legs[Leg.LEFT] == (30.0, 0.9), "nothing reached the robot"


@pytest.mark.realtime
def test_estop_latches_until_reset_and_is_fast(robot, link):
    link.arm()
    result = link.estop()
    assert result.acknowledged and result.reason is None
    assert link.state == LinkState.ESTOPPED and robot.firmware.state.name == "ESTOPPED"
    with pytest.raises(EstopLatched, match="reset before you arm"):
        link.arm()
    link.reset()
    _wait_for(lambda: link.state == LinkState.DISARMED)
    assert not link.latch.held, "an acknowledged RESET releases the latch"


def test_robot_disarms_when_heartbeats_stop(robot):
    # The firmware's own watchdog (1 s, ten of the PC's heartbeat periods): no loaded machine's late
    # heartbeat disarms it before the test stops them.
    link = RobotLink(robot.url, heartbeat_timeout=PATIENT_LINK_S)
    link.connect()
    try:
        link.arm()
        _wait_for(lambda: link.state == LinkState.ARMED)
        link.send_heartbeats = False
        _wait_for(lambda: link.state == LinkState.DISARMED)
        assert link.telemetry.faults & Fault.HEARTBEAT_LOST
    finally:
        link.close()


def test_killing_the_robot_is_a_lost_link(robot):
    link = RobotLink(robot.url, heartbeat_timeout=0.3)
    link.connect()
    reasons = []
    link.on_lost.append(reasons.append)
    robot.stop()
    _wait_for(lambda: link.state == LinkState.DISCONNECTED)
    assert reasons and ("heartbeat" in reasons[0] or "read failed" in reasons[0])
    with pytest.raises(LinkError, match="down"):
        link.arm()
    link.close()


def test_unreachable_robot_is_a_clear_error():
    with pytest.raises(LinkError, match="cannot open"):
        RobotLink("socket://127.0.0.1:9").connect(timeout=0.5)


@pytest.fixture
def jammed():
    """A link on a pty robot (armed, talking) whose PC->robot direction is full: writes block."""
    rig = PtyRobot(RobotState.ARMED).start()
    link = RobotLink(rig.path)
    link.connect()
    rig.jam()
    yield link
    link.close()
    rig.stop()


def test_only_the_robots_radio_is_heard(robot, link):
    link.arm()
    _wait_for(lambda: link.state == LinkState.ARMED)
    robot.inject(received_frame(telemetry(9, RobotState.DISARMED), source64=FOREIGN) * 3)
    _wait_for(lambda: link.foreign_frames == 3)
    time.sleep(0.05)  # the robot's own telemetry keeps coming meanwhile
    assert link.state == LinkState.ARMED and link.telemetry.state == RobotState.ARMED
    assert all(t.reason != "telemetry" or t.after != LinkState.DISARMED for t in link.transitions[1:])
    assert link.counters()["foreign_frames"] == 3 and link.counters()["frames_in"] > 3


def test_a_link_to_another_address_hears_nothing(robot):
    with pytest.raises(LinkError, match="no telemetry"):
        RobotLink(robot.url, robot_address=FOREIGN).connect(timeout=0.3)


def test_estop_on_a_jammed_line_answers_promptly_and_says_so(jammed):
    result = answer_within(JAMMED_ANSWER_S, jammed.estop)
    assert not result.acknowledged and "no acknowledgement" in result.reason
    assert jammed.state == LinkState.ARMED, "not acknowledged: the link does not pretend it stopped"
    assert jammed.counters()["estops_unacknowledged"] == 1


def test_a_blocked_write_is_a_counted_link_error(jammed):
    def set_leg():
        with pytest.raises(LinkError, match="jammed"):
            jammed.set_leg(Leg.LEFT, 30.0, 0.9)
        return True

    assert answer_within(COMMAND_ANSWER_S, set_leg)
    assert jammed.write_timeouts >= 1 and jammed.counters()["write_timeouts"] == jammed.write_timeouts
    assert jammed.port.serial.write_timeout == WRITE_TIMEOUT


@pytest.fixture
def answering():
    """``(rig, link)``: a link on a pty robot (armed) whose rig plays both radios and the firmware's
    rules; set ``rig.delivery_status`` to lose frames on the air."""
    rig = PtyRobot(RobotState.ARMED, answers=True).start()
    link = RobotLink(rig.path)
    link.connect()
    yield rig, link
    link.close()
    rig.stop()


@pytest.fixture
def lossy(answering):
    """``(rig, link)`` after an e-stop lost on the air: not acknowledged, the link starved."""
    rig, link = answering
    rig.delivery_status = NETWORK_ACK_FAILURE
    assert not link.estop().acknowledged and link.state == LinkState.ARMED
    return rig, link


def _kinds(messages) -> list[Kind]:
    return [getattr(message, "kind", None) for message in messages]


def test_an_unacknowledged_estop_stops_the_heartbeats(lossy):
    rig, link = lossy
    time.sleep(WRITE_TIMEOUT)  # the e-stop's last repeat reaches the rig
    given_up = len(rig.sent)
    time.sleep(3.5 * HEARTBEAT_PERIOD)
    sent = _kinds(rig.sent)
    assert Kind.HEARTBEAT not in sent[sent.index(Kind.ESTOP) :], "none from the e-stop on: the watchdog will disarm"
    assert sent[given_up:].count(Kind.ESTOP) >= 2, f"the e-stop is repeated instead, every period: {sent}"
    assert Kind.ESTOP not in _kinds(rig.heard) and link.state == LinkState.ARMED and rig.state == RobotState.ARMED
    with pytest.raises(LinkError, match="reset before you arm"):
        link.arm()


def test_a_lost_estop_gets_through_when_the_air_clears(lossy):
    rig, link = lossy
    time.sleep(2 * HEARTBEAT_PERIOD)
    assert link.state == LinkState.ARMED, "no acknowledgement yet: still not e-stopped"
    cleared = len(rig.heard)
    rig.delivery_status = 0x00
    _wait_for(lambda: link.state == LinkState.ESTOPPED)
    assert rig.state == RobotState.ESTOPPED and rig.heard[cleared].kind == Kind.ESTOP
    assert link.transitions[-1].reason == "e-stop acknowledged (repeated)"
    counters = link.counters()
    assert counters["estops_unacknowledged"] == 1 and counters["retries"] >= 2
    assert counters["delivery_failures"] >= 2 and link.last_delivery_failure == "network ACK failure (0x21)"
    with pytest.raises(EstopLatched, match="the robot acknowledged it"):
        link.arm()  # the robot's latch now, and the PC's until a reset
    link.reset()
    assert link.state == LinkState.DISARMED


def test_a_jammed_line_that_clears_still_delivers_the_estop():
    rig = PtyRobot(RobotState.ARMED, answers=True).start()
    link = RobotLink(rig.path)
    try:
        link.connect()
        rig.jam()
        assert not answer_within(JAMMED_ANSWER_S, link.estop).acknowledged
        time.sleep(WRITE_TIMEOUT * 1.5)  # a write under way when the e-stop gave up ends
        before = link.counters()
        time.sleep(3 * HEARTBEAT_PERIOD)
        jammed = link.counters()
        assert jammed["retries"] > before["retries"] and jammed["write_timeouts"] > before["write_timeouts"]
        assert jammed["frames_out"] == before["frames_out"], "a blocked write is not a frame out"
        assert link.state == LinkState.ARMED and rig.state == RobotState.ARMED
        rig.unjam()
        _wait_for(lambda: link.state == LinkState.ESTOPPED)
        assert rig.state == RobotState.ESTOPPED and link.transitions[-1].reason == "e-stop acknowledged (repeated)"
        # The stop may have travelled in a write that timed out (counted as such) but still left whole.
        _wait_for(lambda: link.counters()["frames_out"] > jammed["frames_out"])  # heartbeats again
    finally:
        link.close()
        rig.stop()


def test_a_failed_reset_keeps_repeating_the_estop(lossy):
    rig, link = lossy
    before = len(rig.sent)
    with pytest.raises(LinkError, match=r"no acknowledgement for RESET \(seq \d+\) in [\d.]+ s after 1 sends"):
        link.reset()  # lost on the air too
    resets = _kinds(rig.sent[before:]).count(Kind.RESET)
    assert resets == 1, "not resent: the e-stop, not yet acknowledged, owns the line"
    rig.delivery_status = 0x00
    _wait_for(lambda: link.state == LinkState.ESTOPPED)
    assert rig.state == RobotState.ESTOPPED


@pytest.mark.realtime
def test_a_new_connection_sends_the_latched_estop_first(lossy):
    rig, link = lossy
    link.close()
    link.connect()
    before, heard_before = len(rig.sent), len(rig.heard)
    time.sleep(3 * HEARTBEAT_PERIOD)
    assert set(_kinds(rig.sent[before:])) == {Kind.ESTOP}, "still lost on the air: the ESTOP, never a heartbeat"
    with pytest.raises(EstopLatched):
        link.arm()
    rig.delivery_status = 0x00
    _wait_for(lambda: link.state == LinkState.ESTOPPED)
    heard = _kinds(rig.heard[heard_before:])
    assert heard[0] == Kind.ESTOP and Kind.HEARTBEAT not in heard[: heard.index(Kind.ESTOP)]
    _wait_for(lambda: _kinds(rig.heard).count(Kind.HEARTBEAT) >= 2)  # acknowledged: heartbeats resume
    assert rig.state == RobotState.ESTOPPED and link.latch.held and link.latch.state.acknowledged


def test_every_frame_has_a_nonzero_frame_id_in_sequence(answering):
    rig, link = answering
    for _ in range(300):  # past 255: the ids wrap
        link.set_leg(Leg.LEFT, 30.0, 0.9)
    counters = link.counters
    _wait_for(lambda: counters()["transmit_status"] == counters()["frames_out"] == len(rig.frame_ids))
    ids = rig.frame_ids
    assert len(ids) >= 300 and ids[0] == 1 and 0 not in ids and 255 in ids
    assert all(after == before % 255 + 1 for before, after in itertools.pairwise(ids)), "in order, wrapping"
    assert counters()["delivery_failures"] == 0 and counters()["retries"] == 0


def test_delivery_failures_are_counted():
    rig = PtyRobot(RobotState.ARMED, answers=True)
    rig.delivery_status, rig.retry_count = ADDRESS_NOT_FOUND, 2  # every frame, from the first
    rig.start()
    link = RobotLink(rig.path)
    try:
        link.connect()
        with pytest.raises(LinkError, match="no acknowledgement"):
            link.set_leg(Leg.LEFT, 30.0, 0.9)
        _wait_for(lambda: link.counters()["delivery_failures"] >= 3)  # the SET_LEG and heartbeats
    finally:
        link.close()  # the reader stops: the counters hold still
        rig.stop()
    counters = link.counters()
    assert counters["delivery_failures"] == counters["transmit_status"] and rig.heard == []
    assert counters["retries"] == 2 * counters["transmit_status"], "the radio's retries, summed"
    assert link.last_delivery_failure == "address not found (0x24)"
    assert counters["foreign_frames"] == 0 and counters["rejected_payloads"] == 0


def test_transmit_status_is_not_the_robots_voice():
    """Transmit Statuses come from the PC's own radio: a robot gone quiet is a lost link, however
    many of them arrive, and none is a foreign frame."""
    rig = PtyRobot(RobotState.ARMED, answers=True).start()
    link = RobotLink(rig.path, heartbeat_timeout=0.6)
    try:
        link.connect()
        rig.talking = False
        quiet = link.counters()["transmit_status"]
        _wait_for(lambda: link.state == LinkState.DISCONNECTED)
        assert "no heartbeat" in link.transitions[-1].reason
        assert link.counters()["transmit_status"] >= quiet + 2, "statuses kept coming while it was quiet"
        assert link.counters()["foreign_frames"] == 0 and link.counters()["rejected_payloads"] == 0
    finally:
        link.close()
        rig.stop()


def test_the_virtual_radio_reports_every_frame_delivered(robot, link, patient_estop):
    link.arm()
    assert link.estop().acknowledged
    counters = link.counters
    _wait_for(lambda: counters()["frames_out"] >= 3 and counters()["transmit_status"] == counters()["frames_out"])
    assert counters()["delivery_failures"] == 0 and link.last_delivery_failure is None
    assert link.port.transmits.retries == 0, "no radio retries on localhost"


def test_both_ends_of_the_virtual_radio_disable_nagle(robot, link):
    _wait_for(lambda: robot._connection is not None)
    for sock in (link.port.serial._socket, robot._connection):
        assert sock.getsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY)


def test_a_telemetry_written_before_the_robot_latched_does_not_unstop_the_link(robot, link, patient_estop):
    # Read after the ESTOP's acknowledgement, an ARMED telemetry the robot wrote before it latched
    # would move the link to armed until the next one (CI saw it in a garbage flood under load).
    link.arm()
    _wait_for(lambda: link.state == LinkState.ARMED)
    assert link.estop().acknowledged
    stopped, heard = len(link.transitions), link._telemetry_heard
    robot.inject(received_frame(telemetry(9, RobotState.ARMED)))
    _wait_for(lambda: link._telemetry_heard >= heard + 3)  # it, and the robot's own after it
    assert link.state == LinkState.ESTOPPED and link.transitions[stopped:] == []
    link.reset()
    _wait_for(lambda: link.state == LinkState.DISARMED)
    assert not link.latch.held


def test_make_safe_disarms_whatever_the_link_believes(robot, link):
    link.arm()
    armed = len(link.transitions)
    robot.inject(received_frame(telemetry(9, RobotState.DISARMED)))  # stale: the robot is armed
    # Believed until the robot's next telemetry, which may follow in the same read: seen in the record.
    _wait_for(lambda: LinkState.DISARMED in [t.after for t in link.transitions[armed:]])
    assert robot.firmware.state == RobotState.ARMED
    assert link.make_safe() == LinkState.DISARMED and robot.firmware.state == RobotState.DISARMED


def test_make_safe_accepts_an_estopped_robot(robot, link, patient_estop):
    assert link.estop().acknowledged
    assert link.make_safe() == LinkState.ESTOPPED and robot.firmware.state == RobotState.ESTOPPED


def test_make_safe_says_when_it_cannot_confirm(jammed):
    error = answer_within(COMMAND_ANSWER_S, _raises_link_error, jammed.make_safe)
    assert "jammed" in str(error) or "no acknowledgement" in str(error), error
    jammed.close()
    with pytest.raises(LinkError, match="down"):
        jammed.make_safe()


def _raises_link_error(call):
    try:
        call()
    except LinkError as error:
        return error
    pytest.fail(f"{call.__name__} did not raise LinkError")


# Late acknowledgements (docs/protocol.md §3): a command is resent, the same message with the same
# sequence number, until acknowledged; a run ends only when the link is really gone.


class LosingAcks(Firmware):
    """The virtual robot's firmware, the acknowledgements of its commands of ``kind`` lost on the
    air: the first ``lose`` of them (None: every one). Keeps each it got, and counts each applied."""

    def __init__(self, kind: Kind, lose: int | None = 1, **fields):
        super().__init__(**fields)
        self.kind, self.lose = kind, lose
        self.got: list = []
        self.applied = 0

    def receive(self, message, now):
        replies = super().receive(message, now)
        if _kind_of(message) != self.kind:
            return replies
        self.got.append(message)
        if self.lose is None or len(self.got) <= self.lose:
            return [reply for reply in replies if not isinstance(reply, Ack)]
        return replies

    def _set_leg(self, message):
        self.applied += self.kind == Kind.SET_LEG
        return super()._set_leg(message)

    def _command(self, kind):
        self.applied += kind == self.kind
        return super()._command(kind)


class Mute(Firmware):
    """The firmware, its radio silent (both its answers and its own heartbeats and telemetry) once
    ``silent`` is set, or from the moment it receives a command of kind ``silent_on``."""

    silent = False
    silent_on: Kind | None = None

    def receive(self, message, now):
        replies = super().receive(message, now)
        self.silent |= _kind_of(message) == self.silent_on
        return [] if self.silent else replies

    def tick(self, now):
        out = super().tick(now)
        return [] if self.silent else out


def _kind_of(message) -> Kind:
    return Kind.SET_LEG if isinstance(message, SetLeg) else message.kind


def _linked(firmware: Firmware, **link_options):
    robot = VirtualRobot(firmware=firmware).start()
    link = RobotLink(robot.url, **link_options)
    link.connect()
    return robot, link


def test_a_set_leg_whose_acknowledgement_is_lost_is_resent_and_applied_once():
    firmware = LosingAcks(Kind.SET_LEG)
    robot, link = _linked(firmware)
    try:
        answer_within(COMMAND_ANSWER_S, link.set_leg, Leg.RIGHT, 35.0, 0.88)
        assert len(firmware.got) >= 2 and set(firmware.got) == {firmware.got[0]}, "the same message, same seq"
        assert firmware.applied == 1 and firmware.legs[Leg.RIGHT] == (35.0, 0.88), "applied once"
        _wait_for(lambda: link.counters()["command_resends"] == len(firmware.got) - 1)
        assert link.state == LinkState.DISARMED
    finally:
        link.close()
        robot.stop()


def test_a_command_never_acknowledged_names_itself_and_how_long_it_waited():
    firmware = LosingAcks(Kind.SET_LEG, lose=None)
    robot, link = _linked(firmware)  # the service's heartbeat timeout: ten of the robot's telemetry periods
    try:
        error = answer_within(COMMAND_ANSWER_S, _raises_link_error, lambda: link.set_leg(Leg.RIGHT, 35.0, 0.88))
        match = re.fullmatch(
            r"no acknowledgement for SET_LEG \(right leg, psi0 35\.00°, zeta0 0\.8800, seq (\d+)\) "
            r"in ([\d.]+) s after (\d+) sends",
            str(error),
        )
        assert match, error
        seq, seconds, sends = int(match[1]), float(match[2]), int(match[3])
        assert seconds >= link.heartbeat_timeout, "given at least as long as a silent robot would be"
        _wait_for(lambda: len(firmware.got) == sends)
        assert sends >= 2 and {m.seq for m in firmware.got} == {seq} and firmware.applied == 1
        assert link.counters()["command_resends"] == sends - 1
        assert link.state == LinkState.DISARMED, "the robot kept talking: the link is not lost"
    finally:
        link.close()
        robot.stop()


def test_a_command_to_a_robot_gone_silent_says_the_link_was_lost():
    firmware = Mute()
    # Silent from the ARM on, not from a moment the test picks: a test thread kept from running for
    # the heartbeat timeout would otherwise send its ARM on a link already lost ("connect first").
    firmware.silent_on = Kind.ARM
    robot, link = _linked(firmware)  # the service's heartbeat timeout, 1 s: ten telemetry periods before the ARM
    try:
        error = answer_within(COMMAND_ANSWER_S, _raises_link_error, link.arm)
        assert str(error).startswith("no acknowledgement for ARM (seq "), error
        assert "the link was lost (no heartbeat from the robot for 1 s)" in str(error), error
        assert link.state == LinkState.DISCONNECTED
    finally:
        link.close()
        robot.stop()


def test_make_safe_resends_its_disarm():
    firmware = LosingAcks(Kind.DISARM)
    robot, link = _linked(firmware)
    try:
        link.arm()
        assert answer_within(COMMAND_ANSWER_S, link.make_safe) == LinkState.DISARMED
        assert len(firmware.got) >= 2 and set(firmware.got) == {firmware.got[0]}
        assert robot.firmware.state == RobotState.DISARMED
    finally:
        link.close()
        robot.stop()


# A restart of the robot (docs/protocol.md §3): named, counted, recorded.

REBOOTED_SEQ = 3 * 16  # the robot's sequence well past the window before it reboots (about 3 s of its traffic)


def test_a_reboot_mid_run_is_named_and_counted(robot, link):
    link.arm()
    link.start()
    assert link.state == LinkState.RUNNING and link.restarts == 0
    _wait_for(lambda: link.telemetry.seq > REBOOTED_SEQ, timeout=10.0)
    robot.reboot()
    _wait_for(lambda: link.restarts == 1)
    assert re.fullmatch(r"robot restarted \(its sequence went back from \d+ to [1-3]\)", link.last_restart)
    _wait_for(lambda: link.state == LinkState.DISARMED)
    restarted = [t for t in link.transitions if t.reason == link.last_restart]
    assert [(t.before, t.after) for t in restarted] == [(LinkState.RUNNING, LinkState.DISARMED)]
    assert link.telemetry.faults & Fault.BOOTED
    time.sleep(0.3)
    assert link.restarts == 1, "one restart, counted once"


def test_a_brown_out_reboot_says_brown_out(robot, link):
    link.arm()
    robot.reboot(brown_out=True)
    _wait_for(lambda: link.restarts == 1)
    assert link.last_restart.startswith("robot restarted (brown-out"), link.last_restart
    _wait_for(lambda: link.state == LinkState.DISARMED)
    assert link.transitions[-1].reason == link.last_restart


def test_a_fresh_connect_to_a_booted_robot_is_no_restart(robot, link):
    assert link.telemetry.faults & Fault.BOOTED, "the virtual robot has just powered up"
    assert link.restarts == 0 and link.last_restart is None
    link.arm()
    _wait_for(lambda: not link.telemetry.faults & Fault.BOOTED)  # the ARM cleared it
    time.sleep(0.2)
    assert link.restarts == 0 and link.last_restart is None


def test_a_second_boot_before_any_arm_is_seen_by_its_sequence(robot, link):
    _wait_for(lambda: link.telemetry.seq > REBOOTED_SEQ, timeout=10.0)
    robot.reboot()
    _wait_for(lambda: link.restarts == 1)
    assert "its sequence went back" in link.last_restart
    assert link.transitions[-1].reason == link.last_restart
    assert (link.transitions[-1].before, link.transitions[-1].after) == (LinkState.DISARMED, LinkState.DISARMED)


def test_a_reboot_while_the_link_was_down_is_counted_on_reconnecting(robot, link):
    link.arm()
    link.close()
    robot.reboot()
    link.connect()
    assert link.restarts == 1 and link.last_restart.startswith("robot restarted")
    assert link.transitions[-1].after == LinkState.DISARMED and link.transitions[-1].reason == link.last_restart


def test_a_robot_that_reboots_under_the_latch_is_estopped_again(robot, link, patient_estop):
    link.arm()
    assert link.estop().acknowledged
    robot.reboot()
    _wait_for(lambda: link.restarts == 1)
    _wait_for(lambda: robot.firmware.state == RobotState.ESTOPPED)
    assert link.state == LinkState.ESTOPPED and link.latch.held
    _wait_for(lambda: link.latch.state.acknowledged)
