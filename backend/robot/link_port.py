"""The link's port and how a frame goes out on it: whole, with a frame id, within a bound.

:class:`LinkPort` opens a pyserial URL (``/dev/ttyUSB0``, ``socket://host:port``, ``loop://``) as
``backend/robot/ports.py`` allows, and writes each message as one XBee Transmit Request to the
robot's radio. A write never blocks its caller longer than :data:`WRITE_TIMEOUT` once the port is
its own (a timeout is counted, ``write_timeouts``, and a :class:`LinkError`); frame ids (1..255)
are taken under the write lock, so they go out in order and each Transmit Status names one frame
(``transmits``). Closing waits for a write under way (each is bounded) and then closes the port.
"""

from __future__ import annotations

import threading
import time

import serial

from backend.robot.link_types import LinkError
from backend.robot.messages import encode
from backend.robot.ports import check_port, no_delay, write_within
from backend.robot.xbee import TransmitLog, encode_frame, tx_request

WRITE_TIMEOUT = 0.1  # [s] the longest any write may block its caller (pyserial's write_timeout)
READ_TIMEOUT = 0.02  # [s]


def open_serial(url: str, baud: int):
    """The pyserial port ``url`` names, if a link may open it (``ports.check_port``), with the link's
    read and write timeouts, set up for small frames. Raises serial.SerialException, ValueError or
    OSError saying why not. The in-process port and the radio process both open theirs here."""
    check_port(url)
    port = serial.serial_for_url(url, baudrate=baud, timeout=READ_TIMEOUT, write_timeout=WRITE_TIMEOUT)
    no_delay(port)
    return port


class LinkPort:
    """One serial port to the PC's radio, frames to ``robot_address``; :meth:`open` before use."""

    def __init__(self, url: str, baud: int, robot_address: int):
        self.url, self.baud, self.robot_address = url, baud, robot_address
        self.frames_out = 0  # Transmit Requests the port took whole within WRITE_TIMEOUT
        self.write_timeouts = 0
        self.transmits = TransmitLog()  # frame ids, and the radio's Transmit Statuses for them
        # Reentrant: the heartbeat thread picks its frame and writes it under it.
        self.write_lock = threading.RLock()
        self._serial = None

    @property
    def is_open(self) -> bool:
        return self._serial is not None

    @property
    def serial(self):
        """The pyserial port (None when closed): for reading, and tests."""
        return self._serial

    def open(self) -> None:
        """Open the port (a LinkError naming it if it cannot be)."""
        try:
            self._serial = open_serial(self.url, self.baud)
        except (serial.SerialException, ValueError, OSError) as error:
            raise LinkError(f"cannot open {self.url}: {error}") from None

    def close(self) -> None:
        with self.write_lock:  # no write is under way on the port being closed (each is bounded)
            port, self._serial = self._serial, None
        if port is not None:
            port.close()

    def read(self) -> bytes:
        """Whatever is waiting, or block (up to READ_TIMEOUT) for the first byte: a full-size read
        would wait out the timeout on every call. Raises serial.SerialException or OSError."""
        port = self._serial
        return port.read(port.in_waiting or 1) if port is not None else b""

    keeps_time = False  # the link's heartbeat thread writes each heartbeat (a ProcessPort keeps the cadence itself)

    def write(self, message, deadline: float | None = None, *, clear_queue: bool = False) -> None:
        """Send one message as a frame, blocking at most WRITE_TIMEOUT once the port is ours; waits
        for the write lock until ``deadline`` (monotonic), or without one as long as another
        writer's bounded write. ``clear_queue``: nothing queued here (a ProcessPort's is)."""
        payload = encode(message)
        wait = -1 if deadline is None else max(0.0, deadline - time.monotonic())
        if not self.write_lock.acquire(timeout=wait):
            raise LinkError("another write is blocked on the port")
        try:
            port = self._serial
            if port is None:
                raise LinkError("the link is down")
            frame_id = self.transmits.next_frame_id()
            frame = encode_frame(tx_request(payload, frame_id=frame_id, destination64=self.robot_address))
            write_within(port, frame, time.monotonic() + WRITE_TIMEOUT)
            self.frames_out += 1
        except serial.SerialTimeoutException:
            # A partial frame may be on the wire: the robot's parser resynchronises on the next start byte.
            self.write_timeouts += 1
            raise LinkError(f"write blocked for {WRITE_TIMEOUT * 1000:.0f} ms: the line is jammed") from None
        except (serial.SerialException, OSError) as error:
            raise LinkError(f"write failed: {error}") from None
        finally:
            self.write_lock.release()
