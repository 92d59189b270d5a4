"""A fault rig for the robot link: on a pty (``os.openpty``, no extra binaries), and a flapping radio.

The link opens :attr:`PtyRobot.path` as it would a USB radio. The rig plays a robot that talks:
it sends TELEMETRY in ``state`` from ``source64`` every ``period`` (while ``talking``). By default
it never reads what the PC sends, so the PC→robot direction fills and then blocks;
:meth:`PtyRobot.jam` fills it at once. With ``answers=True`` it also plays both radios: each
Transmit Request is answered with a Transmit Status (``delivery_status``, ``retry_count``) and,
delivered, goes to the firmware's rules (no watchdog), which reply and may change ``state``.
It keeps what the PC put on the line (``sent``, ``frame_ids``) and what the robot got (``heard``).
A jam pauses the reading until :meth:`PtyRobot.unjam`.

:class:`Radio` flaps one TCP address between the virtual robot, nothing, a silent radio and one that
hangs up; :class:`LinkCalls` watches who opens and closes a :class:`RobotLink`, and how many at once.
"""

from __future__ import annotations

import contextlib
import fcntl
import os
import random
import select
import socket
import threading
import time
import tty

from backend.robot.firmware import Firmware
from backend.robot.link import RobotLink
from backend.robot.messages import ProtocolError, RobotState, Telemetry, decode, encode
from backend.robot.virtual import VirtualRobot
from backend.robot.xbee import (
    DELIVERED,
    ROBOT_ADDRESS,
    FrameError,
    FrameParser,
    encode_frame,
    parse_tx_request,
    rx_packet,
    tx_status,
)
from tests.helpers import free_port

JAM_CHUNK = 4096  # [bytes]
JAM_SETTLE = 3  # fills in a row that find no room
PHASE_S = (0.2, 1.5)  # [s] each phase of the flapping radio lasts between these


def received_frame(message, *, source64: int = ROBOT_ADDRESS) -> bytes:
    """The bytes the PC's radio delivers for ``message`` sent by the radio ``source64``."""
    return encode_frame(rx_packet(encode(message), source64=source64))


def telemetry(seq: int, state: RobotState) -> Telemetry:
    return Telemetry(seq, state, (30.0, 30.0), (0.9, 0.9), 7400, 0)


class PtyRobot:
    def __init__(
        self,
        state: RobotState = RobotState.ARMED,
        *,
        source64: int = ROBOT_ADDRESS,
        period: float = 0.05,
        answers: bool = False,
    ):
        self.master, self._slave = os.openpty()
        tty.setraw(self._slave)  # no line discipline between the frames and the link
        self.path = os.ttyname(self._slave)
        self.state, self.source64, self.period = state, source64, period
        self.talking = True
        self.delivery_status = DELIVERED  # what the Transmit Statuses report (0x24, 0x21: not delivered)
        self.retry_count = 0  # the retries they report
        self.sent: list = []  # messages the PC put on the line, delivered or not, in order
        self.frame_ids: list[int] = []  # theirs
        self.heard: list = []  # those delivered to the robot
        self._rules = Firmware()
        self._parser = FrameParser()
        self._jammed = False
        self._read_lock = threading.Lock()  # held by the reader around each read: a jam waits for it
        self._write_lock = threading.Lock()  # whole frames on the master, whoever writes
        self._stop = threading.Event()
        self._threads = [threading.Thread(target=self._talk, name="pty-robot", daemon=True)]
        if answers:
            self._threads.append(threading.Thread(target=self._answer, name="pty-robot-radio", daemon=True))

    def start(self) -> PtyRobot:
        for thread in self._threads:
            thread.start()
        return self

    def jam(self) -> int:
        """Fill the PC→robot buffer (nobody reads it): every write on the line now blocks. Returns
        the bytes it took."""
        with self._read_lock:
            self._jammed = True
        flags = fcntl.fcntl(self._slave, fcntl.F_GETFL)
        fcntl.fcntl(self._slave, fcntl.F_SETFL, flags | os.O_NONBLOCK)
        filled, settled = 0, 0
        while settled < JAM_SETTLE:  # the kernel moves buffered bytes on to the line discipline's buffer
            before = filled
            with contextlib.suppress(BlockingIOError):
                while True:
                    filled += os.write(self._slave, b"\0" * JAM_CHUNK)
            settled = settled + 1 if filled == before else 0
            time.sleep(0.01)
        return filled

    def unjam(self) -> None:
        """An answering rig reads again: the jam's bytes and whatever the PC got onto the line."""
        with self._read_lock:
            self._jammed = False

    def stop(self) -> None:
        self._stop.set()
        for thread in self._threads:
            thread.join(2)
        os.close(self.master)
        os.close(self._slave)

    def _talk(self) -> None:
        seq = 0
        while not self._stop.wait(self.period):
            seq = (seq + 1) & 0xFFFF
            if self.talking:
                self._put(received_frame(telemetry(seq, self.state), source64=self.source64))

    def _answer(self) -> None:
        while not self._stop.is_set():
            chunk = b""
            with self._read_lock, contextlib.suppress(OSError):
                if not self._jammed and select.select([self.master], [], [], 0.01)[0]:
                    chunk = os.read(self.master, JAM_CHUNK)
            if self._jammed:
                time.sleep(0.01)
            for data in self._parser.feed(chunk):
                with contextlib.suppress(FrameError, ProtocolError):
                    self._radio(*parse_tx_request(data))

    def _radio(self, frame_id: int, _destination: int, payload: bytes) -> None:
        message = decode(payload)
        self.sent.append(message)
        self.frame_ids.append(frame_id)
        if frame_id:
            status = tx_status(frame_id, delivery=self.delivery_status, retries=self.retry_count)
            self._put(encode_frame(status))
        if self.delivery_status != DELIVERED:
            return  # lost on the air: the robot never hears it
        self.heard.append(message)
        self._rules.state = self.state
        replies = self._rules.receive(message, time.monotonic())
        self.state = self._rules.state
        for reply in replies:
            self._put(received_frame(reply, source64=self.source64))

    def _put(self, frame: bytes) -> None:
        with self._write_lock, contextlib.suppress(OSError):
            os.write(self.master, frame)


class Radio:
    """What answers at one address, phase after phase: the virtual robot, nothing (connection
    refused), a radio that accepts and never talks, or one that accepts and hangs up at once."""

    PHASES = ("robot", "refused", "silent", "drops")

    def __init__(self, seed: int = 7):
        self.port = free_port()
        self.url = f"socket://127.0.0.1:{self.port}"
        self.phases: list[str] = []
        self._random = random.Random(seed)
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._flap, name="flapping-radio", daemon=True)

    def flap(self, seconds: float) -> None:
        self._until = time.monotonic() + seconds
        self._thread.start()

    def join(self) -> None:
        self._thread.join(max(0.0, self._until - time.monotonic()) + 2 * PHASE_S[1] + 5.0)
        assert not self._thread.is_alive(), "the flapping radio did not stop"

    @property
    def flapping(self) -> bool:
        return self._thread.is_alive()

    def _flap(self) -> None:
        while time.monotonic() < self._until:
            phase = self._random.choice(self.PHASES)
            self.phases.append(phase)
            getattr(self, f"_{phase}")(self._random.uniform(*PHASE_S))

    def _robot(self, seconds: float) -> None:
        robot = VirtualRobot("127.0.0.1", self.port).start()
        time.sleep(seconds)
        robot.stop()

    def _refused(self, seconds: float) -> None:
        time.sleep(seconds)

    def _silent(self, seconds: float, *, hang_up: bool = False) -> None:
        held = []
        with socket.create_server(("127.0.0.1", self.port)) as server:
            deadline = time.monotonic() + seconds
            while (left := deadline - time.monotonic()) > 0:
                if select.select([server], [], [], left)[0]:
                    connection, _ = server.accept()
                    if hang_up:
                        connection.close()
                    else:
                        held.append(connection)
        for connection in held:
            connection.close()

    def _drops(self, seconds: float) -> None:
        self._silent(seconds, hang_up=True)


class LinkCalls:
    """Who is inside the link's connect and close, and the most connects ever in flight at once."""

    def __init__(self, monkeypatch):
        self.lock = threading.Lock()
        self.connecting = 0
        self.connects = 0
        self.most_connecting = 0
        self.callers: set[str] = set()
        connect, close = RobotLink.connect, RobotLink.close

        def counted_connect(link, *args, **kwargs):
            with self.lock:
                self.connecting += 1
                self.connects += 1
                self.most_connecting = max(self.most_connecting, self.connecting)
                self.callers.add(threading.current_thread().name)
            try:
                return connect(link, *args, **kwargs)
            finally:
                with self.lock:
                    self.connecting -= 1

        def noted_close(link):
            with self.lock:
                self.callers.add(threading.current_thread().name)
            return close(link)

        monkeypatch.setattr(RobotLink, "connect", counted_connect)
        monkeypatch.setattr(RobotLink, "close", noted_close)
