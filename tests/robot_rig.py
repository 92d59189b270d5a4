"""A fault rig for the robot link: on a pty (``os.openpty``, no extra binaries), and a flapping radio.

The link opens :attr:`PtyRobot.path` as it would a USB radio. The rig plays a robot that only
talks: it sends TELEMETRY in ``state`` from ``source64`` every ``period`` and never reads what the
PC sends, so the PC→robot direction fills and then blocks; :meth:`PtyRobot.jam` fills it at once.

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

from backend.robot.link import RobotLink
from backend.robot.messages import RobotState, Telemetry, encode
from backend.robot.virtual import VirtualRobot
from backend.robot.xbee import ROBOT_ADDRESS, encode_frame, rx_packet
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
    def __init__(self, state: RobotState = RobotState.ARMED, *, source64: int = ROBOT_ADDRESS, period: float = 0.05):
        self.master, self._slave = os.openpty()
        tty.setraw(self._slave)  # no line discipline between the frames and the link
        self.path = os.ttyname(self._slave)
        self.state, self.source64, self.period = state, source64, period
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._talk, name="pty-robot", daemon=True)

    def start(self) -> PtyRobot:
        self._thread.start()
        return self

    def jam(self) -> int:
        """Fill the PC→robot buffer (nobody reads it): every write on the line now blocks. Returns
        the bytes it took."""
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

    def stop(self) -> None:
        self._stop.set()
        self._thread.join(2)
        os.close(self.master)
        os.close(self._slave)

    def _talk(self) -> None:
        seq = 0
        while not self._stop.wait(self.period):
            seq = (seq + 1) & 0xFFFF
            with contextlib.suppress(OSError):
                os.write(self.master, received_frame(telemetry(seq, self.state), source64=self.source64))


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
