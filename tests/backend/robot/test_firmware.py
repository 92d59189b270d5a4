"""The robot's side of protocol v1 (backend/robot/firmware.py), without a network: the e-stop latches
until RESET, commands outside the servo limits are refused, silence disarms, and the heartbeat and
telemetry go out on their periods (docs/protocol.md §3)."""

import itertools

from backend.robot.firmware import HEARTBEAT_PERIOD, REPEAT_WINDOW, TELEMETRY_PERIOD, Firmware
from backend.robot.messages import Ack, Command, Fault, Kind, Leg, Result, RobotState, SetLeg, Telemetry


def _send(firmware: Firmware, message, now: float = 0.0) -> list:
    return firmware.receive(message, now)


_SEQ = itertools.count(100)  # each command its own sequence number, as the PC sends them: one reused is a repeat


def _result(firmware: Firmware, kind: Kind, now: float = 0.0) -> Result:
    seq = next(_SEQ)
    ack = _send(firmware, Command(seq, kind), now)[0]
    assert isinstance(ack, Ack) and ack.acked == seq
    return ack.result


def _armed() -> Firmware:
    firmware = Firmware()
    assert _result(firmware, Kind.ARM) == Result.OK and firmware.state == RobotState.ARMED
    return firmware


def test_silence_from_the_pc_disarms_and_raises_a_fault():
    firmware = Firmware(heartbeat_timeout=0.5)
    firmware.receive(Command(1, Kind.ARM), 0.0)
    assert firmware.state == RobotState.ARMED
    firmware.tick(0.4)
    assert firmware.state == RobotState.ARMED
    out = firmware.tick(0.6)
    assert firmware.state == RobotState.DISARMED and firmware.faults & Fault.HEARTBEAT_LOST
    assert any(isinstance(m, Telemetry) and m.state == RobotState.DISARMED for m in out), "and says so at once"
    assert _result(firmware, Kind.ARM, 0.7) == Result.OK and not firmware.faults & Fault.HEARTBEAT_LOST


def test_any_frame_from_the_pc_restarts_the_silence_timer():
    firmware = Firmware(heartbeat_timeout=0.5)
    firmware.receive(Command(1, Kind.ARM), 0.0)
    for now in (0.4, 0.8, 1.2):
        assert firmware.receive(Command(2, Kind.HEARTBEAT), now) == [], "a heartbeat gets no reply"
        firmware.tick(now + 0.3)
    assert firmware.state == RobotState.ARMED


def test_the_estop_latches_until_reset():
    firmware = _armed()
    assert _result(firmware, Kind.ESTOP) == Result.OK and firmware.state == RobotState.ESTOPPED
    legs = dict(firmware.legs)
    for kind in (Kind.ARM, Kind.START, Kind.DISARM):
        assert _result(firmware, kind) == Result.REJECTED_STATE, kind
    leg = _send(firmware, SetLeg(2, Leg.LEFT, 40.0, 0.85))[0]
    assert leg.result == Result.REJECTED_STATE and firmware.legs == legs, "no servo moves while e-stopped"
    assert firmware.state == RobotState.ESTOPPED
    firmware.faults |= Fault.FELL
    assert _result(firmware, Kind.RESET) == Result.OK
    assert firmware.state == RobotState.DISARMED and firmware.faults == 0, "RESET releases it and clears the faults"


def test_silence_never_releases_an_estop():
    firmware = _armed()
    _result(firmware, Kind.ESTOP, 0.0)
    firmware.tick(10.0)
    assert firmware.state == RobotState.ESTOPPED and not firmware.faults & Fault.HEARTBEAT_LOST


def test_a_reset_when_not_estopped_changes_nothing():
    firmware = _armed()
    assert _result(firmware, Kind.RESET) == Result.OK and firmware.state == RobotState.ARMED


def test_a_leg_command_outside_the_servo_limits_is_refused_and_flagged():
    firmware = Firmware()
    refused = _send(firmware, SetLeg(3, Leg.RIGHT, 30.0, 0.99))
    assert refused == [Ack(refused[0].seq, 3, Result.REJECTED_LIMITS)]
    assert firmware.legs[Leg.RIGHT] == (30.0, 0.9) and firmware.faults & Fault.SERVO_LIMIT
    assert _send(firmware, SetLeg(4, Leg.RIGHT, 35.0, 0.88))[0].result == Result.OK
    telemetry = firmware.telemetry()
    assert (telemetry.psi_servo_deg, telemetry.zeta_servo) == ((30.0, 35.0), (0.9, 0.88)), "left, right"


def test_start_only_from_armed_and_a_fall_disarms_a_running_robot():
    firmware = Firmware()
    assert _result(firmware, Kind.START) == Result.REJECTED_STATE and firmware.state == RobotState.DISARMED
    firmware.fell()
    assert firmware.faults == 0, "a robot that is not running cannot fall"
    _result(firmware, Kind.ARM)
    assert _result(firmware, Kind.START) == Result.OK and firmware.state == RobotState.RUNNING
    firmware.fell()
    assert firmware.state == RobotState.DISARMED and firmware.faults & Fault.FELL
    _result(firmware, Kind.ARM)
    assert _result(firmware, Kind.START) == Result.OK and not firmware.faults & Fault.FELL, "a new start clears it"


def test_a_command_is_answered_with_its_ack_then_telemetry():
    firmware = Firmware()
    ack, telemetry = _send(firmware, Command(41, Kind.ARM))
    assert (ack.acked, ack.result) == (41, Result.OK)
    assert isinstance(telemetry, Telemetry) and telemetry.state == RobotState.ARMED
    assert telemetry.seq == ack.seq + 1, "the robot's own sequence numbers"
    unknown, _ = _send(firmware, Command(42, Kind.TELEMETRY))
    assert (unknown.acked, unknown.result) == (42, Result.UNKNOWN) and firmware.state == RobotState.ARMED


def test_messages_that_are_not_for_the_robot_are_ignored():
    firmware = Firmware()
    assert _send(firmware, Ack(1, 1, Result.OK)) == []
    assert _send(firmware, firmware.telemetry()) == []
    assert firmware.state == RobotState.DISARMED


def test_heartbeats_and_telemetry_go_out_on_their_periods():
    firmware = Firmware()

    def kinds(now: float) -> list[str]:
        return ["heartbeat" if isinstance(m, Command) else "telemetry" for m in firmware.tick(now)]

    assert kinds(0.0) == ["heartbeat", "telemetry"]
    assert kinds(TELEMETRY_PERIOD / 2) == []
    assert kinds(TELEMETRY_PERIOD) == ["telemetry"]
    assert kinds(HEARTBEAT_PERIOD) == ["heartbeat", "telemetry"]


# A resent command (docs/protocol.md §3): the same message, same sequence number, after its
# acknowledgement went missing. Acknowledged again with the same result, never applied twice.


def _acks(replies: list) -> list[tuple[int, Result]]:
    return [(m.acked, m.result) for m in replies if isinstance(m, Ack)]


def test_a_resent_start_is_acknowledged_again_and_not_applied_twice():
    firmware = _armed()
    start = Command(7, Kind.START)
    assert _acks(firmware.receive(start, 0.0)) == [(7, Result.OK)] and firmware.state == RobotState.RUNNING
    assert firmware.receive(Command(8, Kind.HEARTBEAT), 0.05) == [], "a heartbeat between them changes nothing"
    again = firmware.receive(start, 0.1)
    assert _acks(again) == [(7, Result.OK)], "the same answer: not refused as a START while running"
    assert isinstance(again[1], Telemetry) and again[1].state == RobotState.RUNNING, "and telemetry, as the first"
    assert firmware.state == RobotState.RUNNING


def test_a_repeat_gets_the_first_answer_even_when_it_was_a_refusal():
    firmware = Firmware()
    outside = SetLeg(3, Leg.RIGHT, 30.0, 0.99)
    assert _acks(firmware.receive(outside, 0.0)) == [(3, Result.REJECTED_LIMITS)]
    firmware.faults = 0
    assert _acks(firmware.receive(outside, 0.1)) == [(3, Result.REJECTED_LIMITS)]
    assert firmware.faults == 0, "not checked again: its fault was raised once"


def test_only_the_same_message_is_a_repeat():
    firmware = Firmware()
    firmware.receive(SetLeg(5, Leg.LEFT, 30.5, 0.9), 0.0)
    firmware.receive(SetLeg(6, Leg.LEFT, 35.0, 0.88), 0.1)
    assert firmware.legs[Leg.LEFT] == (35.0, 0.88), "a new sequence number is a new command, applied"
    firmware.receive(SetLeg(6, Leg.LEFT, 35.0, 0.88), 0.2)
    firmware.receive(SetLeg(5, Leg.LEFT, 30.5, 0.9), 0.3)
    assert firmware.legs[Leg.LEFT] == (35.0, 0.88), "a late repeat of the older command undoes nothing"
    firmware.receive(SetLeg(5, Leg.LEFT, 40.0, 0.85), 0.4)
    assert firmware.legs[Leg.LEFT] == (40.0, 0.85), "the same number with another body (a new PC link): applied"


def test_a_late_reset_does_not_clear_a_newer_estop():
    firmware = _armed()
    firmware.receive(Command(10, Kind.ESTOP), 0.0)
    reset = Command(11, Kind.RESET)
    firmware.receive(reset, 0.1)
    assert firmware.state == RobotState.DISARMED
    firmware.receive(Command(12, Kind.ESTOP), 0.2)
    assert _acks(firmware.receive(reset, 0.3)) == [(11, Result.OK)]
    assert firmware.state == RobotState.ESTOPPED, "the repeat was answered, not applied"


def test_estop_and_disarm_are_always_applied():
    firmware = _armed()
    estop = Command(20, Kind.ESTOP)
    firmware.receive(estop, 0.0)
    firmware.receive(Command(21, Kind.RESET), 0.1)
    assert _acks(firmware.receive(estop, 0.2)) == [(20, Result.OK)]
    assert firmware.state == RobotState.ESTOPPED, "a stop never waits on a memory"
    firmware.receive(Command(22, Kind.RESET), 0.3)
    disarm = Command(23, Kind.DISARM)
    firmware.receive(disarm, 0.4)
    firmware.receive(Command(24, Kind.ARM), 0.5)
    assert _acks(firmware.receive(disarm, 0.6)) == [(23, Result.OK)] and firmware.state == RobotState.DISARMED


def test_a_command_is_remembered_for_a_while_only():
    firmware = Firmware()
    arm = Command(30, Kind.ARM)
    firmware.receive(arm, 0.0)
    firmware.receive(Command(31, Kind.DISARM), 0.1)
    firmware.receive(arm, REPEAT_WINDOW / 2)
    assert firmware.state == RobotState.DISARMED, "within the window: a repeat"
    firmware.receive(arm, REPEAT_WINDOW + 0.5)
    assert firmware.state == RobotState.ARMED, "long after: a new command that happens to match"


# A boot (power-up, brown-out): BOOTED until the PC's first ARM, the sequence from 1.


def test_a_booted_firmware_says_so_until_the_first_arm():
    firmware = Firmware.boot()
    assert firmware.state == RobotState.DISARMED and firmware.faults == Fault.BOOTED
    first = firmware.tick(0.0)
    assert [m.seq for m in first] == [1, 2], "its sequence starts at 1"
    assert all(m.faults == Fault.BOOTED for m in first if isinstance(m, Telemetry))
    ack, telemetry = firmware.receive(Command(1, Kind.ARM), 0.1)
    assert ack.result == Result.OK and not telemetry.faults & Fault.BOOTED, "cleared by the ARM, seen before it"


def test_a_brown_out_boot_says_so_too():
    firmware = Firmware.boot(brown_out=True, heartbeat_timeout=0.3)
    assert firmware.faults == Fault.BOOTED | Fault.BROWNOUT and firmware.heartbeat_timeout == 0.3
    assert Firmware().faults == 0, "a firmware made without a boot has none: the PC has seen its boot"


def test_a_reset_clears_booted_with_the_other_faults():
    firmware = Firmware.boot()
    firmware.receive(Command(1, Kind.ESTOP), 0.0)
    firmware.receive(Command(2, Kind.RESET), 0.1)
    assert firmware.state == RobotState.DISARMED and firmware.faults == 0
