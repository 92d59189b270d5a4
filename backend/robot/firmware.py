"""The robot's side of protocol v1: what the firmware does, and what the virtual robot runs.

A pure state machine: :meth:`Firmware.receive` takes a PC message and returns the replies;
:meth:`Firmware.tick` runs the watchdog and the periodic heartbeat and telemetry. Safety rules
(docs/protocol.md §3): commands outside the servo limits are refused; the e-stop latches until
RESET; silence from the PC for ``heartbeat_timeout`` disarms and raises a fault.

A command the PC sends again (its acknowledgement was late or lost: the same message, the same
sequence number) is acknowledged again with the result it had and not applied again; ESTOP and
DISARM are applied every time (again they change nothing, or make the robot safer).
:meth:`Firmware.boot` is the firmware as at power-up: BOOTED set (and BROWNOUT after one) until the
PC's first ARM, its sequence from 1. ``Firmware()`` is one whose boot the PC has already seen.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass, field

from backend.robot.limits import ServoLimits
from backend.robot.messages import (
    Ack,
    Command,
    Fault,
    Kind,
    Leg,
    Message,
    Result,
    RobotState,
    SetLeg,
    Telemetry,
)

HEARTBEAT_TIMEOUT = 1.0  # [s] silence from the PC after which the robot disarms
HEARTBEAT_PERIOD = 0.2  # [s]
TELEMETRY_PERIOD = 0.1  # [s]
# A command is remembered, to answer a repeat of it, for REPEAT_WINDOW [s] and among the last
# REPEAT_MEMORY: the PC resends for at most its heartbeat timeout and a margin (1.5 s), and may have a
# few commands in flight from different threads (a run's SET_LEG, the operator's DISARM).
REPEAT_WINDOW = 2.0
REPEAT_MEMORY = 8
ALWAYS_APPLIED = (Kind.ESTOP, Kind.DISARM)  # never answered from memory: applying them again is as safe


@dataclass
class Firmware:
    limits: ServoLimits = field(default_factory=ServoLimits)
    heartbeat_timeout: float = HEARTBEAT_TIMEOUT
    battery_mv: int = 7400
    state: RobotState = RobotState.DISARMED
    faults: int = 0
    legs: dict[Leg, tuple[float, float]] = field(
        default_factory=lambda: {Leg.LEFT: (30.0, 0.9), Leg.RIGHT: (30.0, 0.9)}
    )
    _seq: int = 0
    _last_heard: float | None = None
    _last_heartbeat_sent: float = float("-inf")
    _last_telemetry_sent: float = float("-inf")
    # (when, message, result) of the last commands applied, to answer a repeat without applying it
    _applied: deque = field(default_factory=lambda: deque(maxlen=REPEAT_MEMORY))

    @classmethod
    def boot(cls, *, brown_out: bool = False, **fields) -> Firmware:
        """The firmware as at power-up: disarmed, the legs at their defaults, its sequence from 1,
        BOOTED set (and BROWNOUT, after a brown-out) until the PC's first ARM — so the PC sees it in
        the telemetry before that ARM. ``fields``: the robot's configuration (limits, watchdog …)."""
        return cls(faults=Fault.BOOTED | (Fault.BROWNOUT if brown_out else 0), **fields)

    def receive(self, message: Message, now: float) -> list[Message]:
        # Any frame from the PC restarts the silence timer. The PC's repeated ESTOP does too, but
        # ESTOP latches the e-stopped state: it never keeps an armed robot going.
        self._last_heard = now
        if isinstance(message, SetLeg):
            return [self._ack(message.seq, self._once(message, now, lambda: self._set_leg(message)))]
        if not isinstance(message, Command):
            return []  # robot-bound traffic only
        if message.kind == Kind.HEARTBEAT:
            return []  # no acknowledgement, nothing remembered: heartbeats go between a command and its repeat
        result = self._once(message, now, lambda: self._command(message.kind))
        return [self._ack(message.seq, result), self.telemetry()]

    def tick(self, now: float) -> list[Message]:
        out: list[Message] = []
        silent = self._last_heard is None or now - self._last_heard > self.heartbeat_timeout
        if silent and self.state in (RobotState.ARMED, RobotState.RUNNING):
            self.state = RobotState.DISARMED
            self.faults |= Fault.HEARTBEAT_LOST
            out.append(self.telemetry())
        if now - self._last_heartbeat_sent >= HEARTBEAT_PERIOD:
            self._last_heartbeat_sent = now
            out.append(Command(self._next_seq(), Kind.HEARTBEAT))
        if now - self._last_telemetry_sent >= TELEMETRY_PERIOD:
            self._last_telemetry_sent = now
            out.append(self.telemetry())
        return out

    def fell(self) -> None:
        """A jump failed or the body reached the chute's floor: the robot is down, disarmed, and says so."""
        if self.state == RobotState.RUNNING:
            self.state = RobotState.DISARMED
            self.faults |= Fault.FELL

    def telemetry(self) -> Telemetry:
        left, right = self.legs[Leg.LEFT], self.legs[Leg.RIGHT]
        return Telemetry(
            self._next_seq(), self.state, (left[0], right[0]), (left[1], right[1]), self.battery_mv, self.faults
        )

    def forget_repeats(self) -> None:
        """A new PC (the radio associated anew): nothing it sends is a repeat of the last one's."""
        self._applied.clear()

    def _once(self, message: Message, now: float, apply) -> Result:
        """``apply()``'s result, or, for a repeat of a command applied within REPEAT_WINDOW (the same
        message: type, sequence number and body), the result it had, without applying it again."""
        if getattr(message, "kind", None) in ALWAYS_APPLIED:
            return apply()
        for when, applied, result in self._applied:
            if applied == message and now - when <= REPEAT_WINDOW:
                return result
        result = apply()
        self._applied.append((now, message, result))
        return result

    def _set_leg(self, message: SetLeg) -> Result:
        if self.state == RobotState.ESTOPPED:
            return Result.REJECTED_STATE
        if not self.limits.allows(message.psi0_deg, message.zeta0):
            self.faults |= Fault.SERVO_LIMIT
            return Result.REJECTED_LIMITS
        self.legs[message.leg] = (message.psi0_deg, message.zeta0)
        return Result.OK

    def _command(self, kind: Kind) -> Result:
        if kind == Kind.ESTOP:
            self.state = RobotState.ESTOPPED
            return Result.OK
        if kind == Kind.RESET:
            if self.state == RobotState.ESTOPPED:
                self.state = RobotState.DISARMED
                self.faults = 0
            return Result.OK
        if self.state == RobotState.ESTOPPED:
            return Result.REJECTED_STATE
        if kind == Kind.ARM:
            if self.state == RobotState.DISARMED:
                self.state = RobotState.ARMED
                self.faults &= ~(Fault.HEARTBEAT_LOST | Fault.BOOTED)  # the PC has seen the boot: it arms
            return Result.OK
        if kind == Kind.START:
            if self.state != RobotState.ARMED:
                return Result.REJECTED_STATE
            self.state = RobotState.RUNNING
            self.faults &= ~Fault.FELL
            return Result.OK
        if kind == Kind.DISARM:
            self.state = RobotState.DISARMED
            return Result.OK
        return Result.UNKNOWN

    def _ack(self, seq: int, result: Result) -> Ack:
        return Ack(self._next_seq(), seq, result)

    def _next_seq(self) -> int:
        self._seq = (self._seq + 1) & 0xFFFF
        return self._seq
