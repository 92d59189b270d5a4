"""The virtual robot's radio: protocol v1 over TCP, the firmware state machine behind it.

PC software connects with the pyserial URL ``socket://HOST:PORT`` exactly as it would open the
XBee's serial port. One PC at a time; a new connection replaces the old one (like a radio
re-association). Given a tracker address, the body moves (:mod:`backend.robot.climber`) while
the firmware is running, and the camera's view of it streams there over UDP.

The radio answers a Transmit Request with a non-zero frame id as an XBee does, with a Transmit
Status ahead of anything the robot replies: delivered (0x00, no retries) when it is addressed to
the robot's radio, else "address not found" (0x24) and the robot never sees it.

The robot powers up when made (:meth:`Firmware.boot`: BOOTED until the PC's first ARM), and
:meth:`VirtualRobot.reboot` restarts it as a brown-out or a reset would, on the same connection.
"""

from __future__ import annotations

import contextlib
import logging
import select
import socket
import threading
import time

from backend.robot.climber import Climber
from backend.robot.firmware import Firmware
from backend.robot.messages import ProtocolError, RobotState, decode, encode
from backend.robot.xbee import (
    ADDRESS_NOT_FOUND,
    DELIVERED,
    ROBOT_ADDRESS,
    FrameError,
    FrameParser,
    encode_frame,
    parse_tx_request,
    rx_packet,
    tx_status,
)

log = logging.getLogger("parkourlab.robot")
TICK = 0.02  # [s] watchdog and telemetry resolution


class VirtualRobot:
    def __init__(
        self,
        host: str = "127.0.0.1",
        port: int = 0,
        *,
        firmware: Firmware | None = None,
        tracker_to: tuple[str, int] | None = None,
        **climber_options,
    ):
        """``tracker_to``: where to stream the body's tracker datagrams (None: no motion, radio only).
        ``climber_options`` go to :class:`backend.robot.climber.Climber` (noise, speed, seed, the
        camera's ``tracker_protocol``: PKT1 or NatNet ...). Without ``firmware``, one just powered up."""
        self.firmware = firmware or Firmware.boot()
        self.server = socket.create_server((host, port))
        self.address = self.server.getsockname()
        self.lock = threading.Lock()  # the firmware is shared by the reader and the ticker
        self._send_lock = threading.Lock()  # whole frames on the connection, whoever sends
        self.parser = FrameParser()
        self.rejected_payloads = 0
        self._connection: socket.socket | None = None
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._serve, name="virtual-robot", daemon=True)
        self.climber = None
        if tracker_to is not None:
            self.climber = Climber(self._legs, self._running, self._fell, tracker_to, **climber_options)

    @property
    def url(self) -> str:
        return f"socket://{self.address[0]}:{self.address[1]}"

    def start(self) -> VirtualRobot:
        self._thread.start()
        if self.climber is not None:
            self.climber.start()
        return self

    def stop(self) -> None:
        self._stop.set()
        self._thread.join(5)
        if self.climber is not None:
            self.climber.stop()
        self._close_connection()
        self.server.close()

    def inject(self, data: bytes) -> None:
        """Bytes the PC's radio delivers besides the robot's (another radio's frames, line noise):
        the fault tests' way to put them on the line."""
        with self._send_lock:
            if self._connection is not None:
                self._connection.sendall(data)

    def reboot(self, brown_out: bool = False) -> None:
        """The robot restarts (a reset, or a brown-out: ``brown_out``): its firmware replaced by one as
        at power-up (disarmed, the legs at their defaults, its sequence from 1, BOOTED, and BROWNOUT if
        asked), its configuration kept. The radio keeps its association: the PC's connection stays.
        The body stops where it is, as the firmware that ran the climb is gone (it falls)."""
        with self.lock:
            old = self.firmware
            self.firmware = Firmware.boot(
                brown_out=brown_out, limits=old.limits, heartbeat_timeout=old.heartbeat_timeout,
                battery_mv=old.battery_mv,
            )  # fmt: skip

    def _legs(self) -> dict:
        with self.lock:
            return dict(self.firmware.legs)

    def _running(self) -> bool:
        return self.firmware.state == RobotState.RUNNING and not self._stop.is_set()

    def _fell(self) -> None:
        with self.lock:
            self.firmware.fell()

    def _serve(self) -> None:
        # One thread waits on the listening socket and the connection at once: a command is
        # answered as soon as it arrives, and the watchdog still runs every TICK.
        next_tick = time.monotonic()
        while not self._stop.is_set():
            sockets = [self.server] + ([self._connection] if self._connection is not None else [])
            ready, _, _ = select.select(sockets, [], [], max(0.0, next_tick - time.monotonic()))
            if self.server in ready:
                connection, _ = self.server.accept()
                # No Nagle: an acknowledgement must not wait for the ACK of the telemetry before it.
                connection.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
                self._close_connection()
                self._connection = connection
                self.parser = FrameParser()
                with self.lock:  # a new association: a new PC, whose commands are none of the old one's
                    self.firmware.forget_repeats()
            elif ready:
                self._exchange(ready[0])
            if time.monotonic() >= next_tick:
                next_tick = time.monotonic() + TICK
                self._send(self._tick())

    def _exchange(self, connection: socket.socket) -> None:
        try:
            chunk = connection.recv(4096)
        except OSError:
            self._close_connection()
            return
        if not chunk:
            self._close_connection()
            return
        for data in self.parser.feed(chunk):
            try:
                frame_id, destination, payload = parse_tx_request(data)
            except FrameError:
                self.rejected_payloads += 1
                continue
            delivered = destination == ROBOT_ADDRESS
            # Frame id 0 asks for no status; a payload is delivered whatever it holds (the robot judges).
            delivery = DELIVERED if delivered else ADDRESS_NOT_FOUND
            status = encode_frame(tx_status(frame_id, delivery=delivery)) if frame_id else b""
            self._send(self._receive(payload) if delivered else [], status)

    def _receive(self, payload: bytes) -> list:
        """The firmware's replies to a payload its radio delivered (none to a malformed one)."""
        try:
            message = decode(payload)
        except ProtocolError:
            self.rejected_payloads += 1
            return []
        with self.lock:
            return self.firmware.receive(message, time.monotonic())

    def _tick(self) -> list:
        with self.lock:
            return self.firmware.tick(time.monotonic())

    def _send(self, messages: list, status_frame: bytes = b"") -> None:
        """The robot's ``messages`` as Receive Packets, after the PC radio's own ``status_frame``."""
        if self._connection is None or not (messages or status_frame):
            return
        frames = (encode_frame(rx_packet(encode(message), source64=ROBOT_ADDRESS)) for message in messages)
        data = status_frame + b"".join(frames)
        try:
            with self._send_lock:
                self._connection.sendall(data)
        except OSError:
            self._close_connection()

    def _close_connection(self) -> None:
        if self._connection is not None:
            with contextlib.suppress(OSError):
                self._connection.close()
            self._connection = None
