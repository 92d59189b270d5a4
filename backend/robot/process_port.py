"""The link's port kept by a radio process (:mod:`backend.robot.radio_process`), seen as a LinkPort.

:class:`ProcessPort` has :class:`~backend.robot.link_port.LinkPort`'s interface, and
:class:`~backend.robot.link.RobotLink` uses it unchanged: ``write`` hands the radio process a
message and waits for how its write went (bounded as the in-process port's), ``read`` returns what
the radio process read from the robot. What differs is the heartbeat: :meth:`queue` hands the radio
process the frames for its own cadence (the service's lease, topped up every period), and
:meth:`drop_queued` takes them back before an e-stop owns the line or a RESET goes. The process is
started at :meth:`open` (a LinkError with its reason if the port cannot be opened) and ended at
:meth:`close`, and on its own when the service dies.
"""

from __future__ import annotations

import os
import socket
import subprocess
import sys
import threading
import time
from pathlib import Path

from backend.robot import radio_process as radio
from backend.robot.link_port import READ_TIMEOUT, WRITE_TIMEOUT
from backend.robot.link_types import LinkError
from backend.robot.messages import encode
from backend.robot.ports import check_port
from backend.robot.xbee import TransmitLog

START_TIMEOUT = 10.0  # [s] for the radio process to open the port (a cold interpreter on a loaded machine)
ANSWER_MARGIN = 1.0  # [s] beyond a write's bound for the radio process' answer (it may wait for the CPU)
END_TIMEOUT = 2.0  # [s] for the radio process to end once told to, before it is killed
PROJECT_ROOT = Path(__file__).resolve().parents[2]  # where ``backend`` is importable from


class ProcessPort:
    """One radio process for one connection; :meth:`open` before use. Frames to ``robot_address``."""

    keeps_time = True  # the radio process writes the heartbeats the link queues, on its own cadence

    def __init__(self, url: str, baud: int, robot_address: int):
        self.url, self.baud, self.robot_address = url, baud, robot_address
        self.frames_out = 0  # as the radio process last said: frames written whole (heartbeats too)
        self.write_timeouts = 0
        self.transmits = TransmitLog()  # the Transmit Statuses heard (the radio process numbers the frames)
        self.queued = 0  # frames the radio process holds for its cadence, as it last said
        self.write_lock = threading.RLock()  # one request, and its answer, at a time
        self._number = 0  # the last request's number
        self._process: subprocess.Popen | None = None
        self._control: socket.socket | None = None
        self._data: socket.socket | None = None

    @property
    def is_open(self) -> bool:
        return self._control is not None

    @property
    def serial(self):
        """None: the serial port is the radio process' (tests of the in-process port reach into it)."""
        return None

    @property
    def pid(self) -> int | None:
        return None if self._process is None else self._process.pid

    def open(self) -> None:
        """Start the radio process and wait until it has the port open (a LinkError naming it if not)."""
        try:
            check_port(self.url)
        except ValueError as error:
            raise LinkError(f"cannot open {self.url}: {error}") from None
        control, control_child = socket.socketpair(socket.AF_UNIX, socket.SOCK_SEQPACKET)
        # A byte stream: a datagram socket holds only max_dgram_qlen (10) messages however small,
        # and a service held for a moment would lose the robot's frames behind them.
        data, data_child = socket.socketpair(socket.AF_UNIX, socket.SOCK_STREAM)
        path = [str(PROJECT_ROOT), os.environ.get("PYTHONPATH")]
        env = dict(os.environ, PYTHONPATH=os.pathsep.join(filter(None, path)))
        command = [sys.executable, "-m", radio.__name__, self.url, str(self.baud), str(self.robot_address),
                   str(control_child.fileno()), str(data_child.fileno())]  # fmt: skip
        try:
            process = subprocess.Popen(command, pass_fds=(control_child.fileno(), data_child.fileno()), env=env,
                                       stdin=subprocess.DEVNULL, cwd=PROJECT_ROOT)  # fmt: skip
        except OSError as error:
            for sock in (control, data):
                sock.close()
            raise LinkError(f"cannot start the radio process for {self.url}: {error}") from None
        finally:
            control_child.close()
            data_child.close()
        control.settimeout(START_TIMEOUT)
        try:
            first = control.recv(radio.CHUNK)
        except TimeoutError:
            first = b""
        if first != radio.OPENED:
            failed = first[:1] == radio.FAILED
            reason = first[1:].decode(errors="replace") if failed else "the radio process did not start"
            _end(process, control, data)
            raise LinkError(f"cannot open {self.url}: {reason}")
        data.settimeout(READ_TIMEOUT)
        self._process, self._control, self._data = process, control, data

    def close(self) -> None:
        """End the radio process (it closes the port), after a request under way is answered."""
        with self.write_lock:
            process, control, data = self._process, self._control, self._data
            self._process = self._control = self._data = None
        if process is not None:
            _end(process, control, data)

    def read(self) -> bytes:
        """What the radio process read from the robot (b"" after READ_TIMEOUT without any). Raises
        OSError once it says the port failed, or has ended."""
        data = self._data
        if data is None:
            return b""
        try:
            chunk = data.recv(radio.CHUNK)
        except TimeoutError:
            return b""
        if not chunk:
            raise OSError("the radio process lost the port")
        return chunk

    def write(self, message, deadline: float | None = None, *, clear_queue: bool = False) -> None:
        """Have the radio process write one message as a frame now, within WRITE_TIMEOUT of taking
        it; waits for the port until ``deadline`` (monotonic) as LinkPort.write does. ``clear_queue``:
        the frames queued for the cadence are dropped first, in the same request (an e-stop's)."""
        kind = radio.WRITE_ALONE if clear_queue else radio.WRITE
        status, reason = self._request(kind, encode(message), deadline, WRITE_TIMEOUT)
        if status == radio.TIMED_OUT:
            raise LinkError(f"write blocked for {WRITE_TIMEOUT * 1000:.0f} ms: the line is jammed")
        if status != radio.OK:
            raise LinkError(f"write failed: {reason}")

    def queue(self, message) -> None:
        """Hand the radio process ``message`` for its cadence, and renew its lease: LEASE from now."""
        self._request(radio.QUEUE, encode(message), None, radio.LEASE)

    def drop_queued(self) -> None:
        """Take back every frame queued for the cadence (none is written after this returns)."""
        self._request(radio.DROP, b"", None, 0.0)

    def _request(self, kind: bytes, payload: bytes, deadline: float | None, life: float) -> tuple[int, str]:
        """Send one request, once the port is ours (by ``deadline``), and wait for its answer (until
        ``deadline`` and the write's bound, or ANSWER_MARGIN more without one); ``life`` [s] from
        now: the write's bound, or the lease a queued frame renews."""
        wait = -1 if deadline is None else max(0.0, deadline - time.monotonic())
        if not self.write_lock.acquire(timeout=wait):
            raise LinkError("another write is blocked on the port")
        try:
            control = self._control
            if control is None:
                raise LinkError("the link is down")
            now = time.monotonic()
            answer_by = now + WRITE_TIMEOUT + (ANSWER_MARGIN if deadline is None else max(0.0, deadline - now))
            self._number = (self._number + 1) & 0xFFFF
            try:
                control.sendall(kind + radio.HEAD.pack(self._number, now + life) + payload)
                while True:  # an answer to an earlier request, given up on, is passed over
                    control.settimeout(max(0.001, answer_by - time.monotonic()))
                    answer = control.recv(radio.CHUNK)
                    if len(answer) < radio.ANSWER.size:
                        raise LinkError("the radio process has ended")
                    number, status, self.frames_out, self.write_timeouts, self.queued = radio.ANSWER.unpack_from(answer)
                    if number == self._number:
                        return status, answer[radio.ANSWER.size :].decode(errors="replace")
            except OSError as error:  # TimeoutError among them: a radio process that stopped answering
                raise LinkError(f"the radio process did not answer: {error}") from None
        finally:
            self.write_lock.release()


def _end(process: subprocess.Popen, control: socket.socket, data: socket.socket) -> None:
    """Close the service's ends (the radio process reads the end of file, closes the port, ends)."""
    control.close()
    try:
        process.wait(END_TIMEOUT)
    except subprocess.TimeoutExpired:
        process.kill()
        process.wait()
    data.close()
