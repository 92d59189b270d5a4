"""The PC's side of the robot link: a pyserial URL, protocol v1, heartbeats, and safety.

``RobotLink(url)`` opens ``/dev/ttyUSB0`` (the XBee), ``socket://host:port`` (the virtual robot)
or ``loop://`` — pyserial's URLs. A reader thread decodes frames and tracks the robot's state
from its telemetry and acknowledgements; a heartbeat thread keeps the robot armed. Silence from
the robot for ``heartbeat_timeout`` is a lost link: the state becomes ``disconnected`` and the
``on_lost`` callbacks run (a live run aborts, keeping what it recorded). Leg commands are checked
against the servo limits before they are sent. Every state change is kept in ``transitions``.
"""

from __future__ import annotations

import enum
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass

import serial

from backend.robot.limits import ServoLimits
from backend.robot.messages import (
    Ack,
    Command,
    Kind,
    Leg,
    ProtocolError,
    Result,
    RobotState,
    SetLeg,
    Telemetry,
    decode,
    encode,
)
from backend.robot.xbee import ROBOT_ADDRESS, FrameError, FrameParser, encode_frame, parse_rx_packet, tx_request

HEARTBEAT_PERIOD = 0.2  # [s]
HEARTBEAT_TIMEOUT = 1.0  # [s]
COMMAND_TIMEOUT = 0.5  # [s] for an acknowledgement
ESTOP_REPEAT = 0.02  # [s] between e-stop repeats until acknowledged
READ_TIMEOUT = 0.02  # [s]


class LinkState(enum.StrEnum):
    DISCONNECTED = "disconnected"
    DISARMED = "disarmed"
    ARMED = "armed"
    RUNNING = "running"
    ESTOPPED = "estopped"


_FROM_ROBOT = {
    RobotState.DISARMED: LinkState.DISARMED,
    RobotState.ARMED: LinkState.ARMED,
    RobotState.RUNNING: LinkState.RUNNING,
    RobotState.ESTOPPED: LinkState.ESTOPPED,
}


class LinkError(RuntimeError):
    """The robot did not answer, refused a command, or the link is down."""


@dataclass(frozen=True)
class Transition:
    time: float  # time.time()
    before: LinkState
    after: LinkState
    reason: str


class RobotLink:
    def __init__(
        self,
        url: str,
        *,
        baud: int = 57_600,
        limits: ServoLimits | None = None,
        heartbeat_timeout: float = HEARTBEAT_TIMEOUT,
        robot_address: int = ROBOT_ADDRESS,
    ):
        self.url = url
        self.baud = baud
        self.limits = limits or ServoLimits()
        self.heartbeat_timeout = heartbeat_timeout
        self.robot_address = robot_address
        self.state = LinkState.DISCONNECTED
        self.transitions: list[Transition] = []
        self.telemetry: Telemetry | None = None
        self.parser = FrameParser()
        self.rejected_payloads = 0
        self.on_lost: list[Callable[[str], None]] = []
        self._port = None
        self._seq = 0
        self._acks: dict[int, tuple[threading.Event, list[Ack]]] = {}
        self._lock = threading.Lock()
        self._write_lock = threading.Lock()
        self._last_heard = 0.0
        self._stop = threading.Event()
        self._threads: list[threading.Thread] = []
        self.send_heartbeats = True  # tests turn this off to starve the robot

    # Connection -----------------------------------------------------------------------------
    def connect(self, timeout: float = 3.0) -> LinkState:
        """Open the port and wait for the robot's first telemetry."""
        self.telemetry = None
        self.parser = FrameParser()
        try:
            self._port = serial.serial_for_url(self.url, baudrate=self.baud, timeout=READ_TIMEOUT)
        except (serial.SerialException, ValueError, OSError) as error:
            raise LinkError(f"cannot open {self.url}: {error}") from None
        self._stop.clear()
        self._last_heard = time.monotonic()
        self._threads = [
            threading.Thread(target=self._read_loop, name="robot-link-reader", daemon=True),
            threading.Thread(target=self._heartbeat_loop, name="robot-link-heartbeat", daemon=True),
        ]
        for thread in self._threads:
            thread.start()
        deadline = time.monotonic() + timeout
        while self.telemetry is None:
            if time.monotonic() > deadline:
                self.close()
                raise LinkError(f"no telemetry from the robot at {self.url} within {timeout:g} s")
            time.sleep(0.005)
        return self.state

    def reconnect(self, timeout: float = 1.0) -> LinkState:
        """Close what is left of a dropped link and connect again (the robot stays as it decided:
        after silence it has disarmed itself)."""
        self.close()
        return self.connect(timeout)

    def close(self) -> None:
        self._stop.set()
        for thread in self._threads:
            if thread is not threading.current_thread():
                thread.join(2)
        if self._port is not None:
            self._port.close()
            self._port = None
        self._move(LinkState.DISCONNECTED, "closed")

    # Commands -------------------------------------------------------------------------------
    def arm(self) -> None:
        self._command(Command(self._next_seq(), Kind.ARM), expect=LinkState.ARMED)

    def start(self) -> None:
        """Armed robot: launch and keep jumping with the legs' current controls."""
        self._command(Command(self._next_seq(), Kind.START), expect=LinkState.RUNNING)

    def disarm(self) -> None:
        self._command(Command(self._next_seq(), Kind.DISARM), expect=LinkState.DISARMED)

    def reset(self) -> None:
        self._command(Command(self._next_seq(), Kind.RESET), expect=LinkState.DISARMED)

    def set_leg(self, leg: Leg, psi0_deg: float, zeta0: float) -> None:
        """Send a leg's controls for its next touchdown; outside the servo limits, refuse to send."""
        self.limits.check(psi0_deg, zeta0)
        self._command(SetLeg(self._next_seq(), leg, psi0_deg, zeta0))

    def estop(self, timeout: float = 2.0) -> float:
        """Emergency stop: repeat ESTOP until acknowledged; returns the latency to the ack [s]."""
        started = time.monotonic()
        message = Command(self._next_seq(), Kind.ESTOP)
        event, _box = self._expect(message.seq)
        try:
            while not event.is_set():
                if time.monotonic() - started > timeout:
                    raise LinkError(f"e-stop not acknowledged within {timeout:g} s")
                self._write(message)
                event.wait(ESTOP_REPEAT)
        finally:
            self._acks.pop(message.seq, None)
        self._move(LinkState.ESTOPPED, "e-stop acknowledged")
        return time.monotonic() - started

    # Internals ------------------------------------------------------------------------------
    def _command(self, message, expect: LinkState | None = None) -> Ack:
        """Send, wait for the acknowledgement, and (``expect``) for the telemetry showing its effect."""
        if self.state == LinkState.DISCONNECTED:
            raise LinkError("the link is down; connect first")
        event, box = self._expect(message.seq)
        try:
            self._write(message)
            if not event.wait(COMMAND_TIMEOUT):
                raise LinkError(f"no acknowledgement for {type(message).__name__} within {COMMAND_TIMEOUT:g} s")
        finally:
            self._acks.pop(message.seq, None)
        ack = box[0]
        name = message.kind.name if isinstance(message, Command) else type(message).__name__
        if ack.result != Result.OK:
            raise LinkError(f"the robot refused {name}: {ack.result.name.lower()}")
        deadline = time.monotonic() + COMMAND_TIMEOUT
        while expect is not None and self.state != expect:
            if time.monotonic() > deadline:
                raise LinkError(f"{name} acknowledged but the robot reports {self.state.value}, not {expect.value}")
            time.sleep(0.001)
        return ack

    def _expect(self, seq: int) -> tuple[threading.Event, list[Ack]]:
        entry = (threading.Event(), [])
        self._acks[seq] = entry
        return entry

    def _write(self, message) -> None:
        frame = encode_frame(tx_request(encode(message), frame_id=0, destination64=self.robot_address))
        with self._write_lock:
            if self._port is None:
                raise LinkError("the link is down")
            try:
                self._port.write(frame)
            except (serial.SerialException, OSError) as error:
                raise LinkError(f"write failed: {error}") from None

    def _next_seq(self) -> int:
        with self._lock:
            self._seq = (self._seq + 1) & 0xFFFF
            return self._seq

    def _read_loop(self) -> None:
        while not self._stop.is_set():
            try:
                # Whatever is waiting, or block (up to READ_TIMEOUT) for the first byte: a full-size
                # read would wait out the timeout on every call.
                port = self._port
                chunk = port.read(port.in_waiting or 1) if port is not None else b""
            except (serial.SerialException, OSError):
                chunk = b""
                self._lost("read failed")
                return
            for data in self.parser.feed(chunk):
                try:
                    message = decode(parse_rx_packet(data).payload)
                except (FrameError, ProtocolError):
                    self.rejected_payloads += 1
                    continue
                self._last_heard = time.monotonic()
                self._handle(message)
            if time.monotonic() - self._last_heard > self.heartbeat_timeout:
                self._lost(f"no heartbeat from the robot for {self.heartbeat_timeout:g} s")
                return

    def _handle(self, message) -> None:
        if isinstance(message, Ack):
            entry = self._acks.get(message.acked)
            if entry is not None:
                entry[1].append(message)
                entry[0].set()
        elif isinstance(message, Telemetry):
            self.telemetry = message
            self._move(_FROM_ROBOT[message.state], "telemetry")

    def _heartbeat_loop(self) -> None:
        while not self._stop.wait(HEARTBEAT_PERIOD):
            if self.send_heartbeats:
                try:
                    self._write(Command(self._next_seq(), Kind.HEARTBEAT))
                except LinkError:
                    return

    def _lost(self, reason: str) -> None:
        self._stop.set()
        self._move(LinkState.DISCONNECTED, reason)
        for callback in list(self.on_lost):
            callback(reason)

    def _move(self, state: LinkState, reason: str) -> None:
        with self._lock:
            if state == self.state:
                return
            self.transitions.append(Transition(time.time(), self.state, state, reason))
            self.state = state
