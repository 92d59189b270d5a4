"""A fault rig for the robot link on a pty (``os.openpty``, no extra binaries).

The link opens :attr:`PtyRobot.path` as it would a USB radio. The rig plays a robot that only
talks: it sends TELEMETRY in ``state`` from ``source64`` every ``period`` and never reads what the
PC sends, so the PC→robot direction fills and then blocks; :meth:`PtyRobot.jam` fills it at once.
"""

from __future__ import annotations

import contextlib
import fcntl
import os
import threading
import time
import tty

from backend.robot.messages import RobotState, Telemetry, encode
from backend.robot.xbee import ROBOT_ADDRESS, encode_frame, rx_packet

JAM_CHUNK = 4096  # [bytes]
JAM_SETTLE = 3  # fills in a row that find no room


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
