"""The robot's side of protocol v1 (backend/robot/firmware.py), without a network: the e-stop latches
until RESET, commands outside the servo limits are refused, silence disarms, and the heartbeat and
telemetry go out on their periods (docs/protocol.md §3)."""

from backend.robot.firmware import HEARTBEAT_PERIOD, TELEMETRY_PERIOD, Firmware
from backend.robot.messages import Ack, Command, Fault, Kind, Leg, Result, RobotState, SetLeg, Telemetry


def _send(firmware: Firmware, message, now: float = 0.0) -> list:
    return firmware.receive(message, now)


def _result(firmware: Firmware, kind: Kind, now: float = 0.0) -> Result:
    ack = _send(firmware, Command(1, kind), now)[0]
    assert isinstance(ack, Ack) and ack.acked == 1
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
