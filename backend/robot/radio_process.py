"""The radio process: the link's port in a process of its own, keeping the heartbeat's time.

The service's interpreter is shared by the web server, live runs and compiled kernels (a numba
kernel holds the GIL for its whole call), and a heartbeat thread in it waited as long as they did:
the robot saw gaps of 411-802 ms at a 100 ms cadence. Here one small process per connection owns
the serial port. It writes what the service hands it at once (commands, e-stops: each answered with
how the write went), forwards every byte it reads to the service, and writes the frames the service
queued for the cadence — heartbeats, or an unacknowledged ESTOP in their place — one every
:data:`HEARTBEAT_PERIOD`, on its own clock.

The queue comes with the service's lease: each frame it queues renews it until :data:`LEASE` from
then, and the service queues one each period, topping the queue up to :data:`LEASE_FRAMES`. A
service that stops (hung, or GIL-bound for longer than the lease) stops the heartbeats half a
second later, and the robot's own watchdog disarms it; a service that dies closes the control
socket, and this process closes the port and ends. It ignores SIGINT and SIGTERM: a Ctrl-C to the
service's process group must leave the port to the service's shutdown, which ends a live run
through it (every ending disarms the robot) before it closes the link.

Started by :class:`backend.robot.process_port.ProcessPort` as ``python -m backend.robot.radio_process
URL BAUD ADDRESS CONTROL_FD DATA_FD``. Wire (control: ``socket.SOCK_SEQPACKET``, one message each):

- service -> here, control: a kind, a head (:data:`HEAD`) and a payload: ``W`` deadline payload
  (write now; answered), ``X`` the same after dropping the queue (an e-stop), ``Q`` lease payload
  (queue for the cadence, the lease renewed until then; answered), ``D`` (drop the queue;
  answered); end of file: close the port and end.
- here -> service, control: first ``O`` (port open) or ``E`` reason; then one :data:`ANSWER` per request.
- here -> service, data (``socket.SOCK_STREAM``): the bytes read from the port, as they come; end of
  file: the port failed.
"""

from __future__ import annotations

import collections
import contextlib
import os
import signal
import socket
import struct
import sys
import threading
import time

import serial

from backend.robot.link_port import READ_TIMEOUT, WRITE_TIMEOUT, open_serial
from backend.robot.ports import write_within
from backend.robot.xbee import TransmitLog, encode_frame, tx_request

LEASE = 0.5  # [s] how long each queued frame renews the lease: a service silent for longer stops the heartbeats
LEASE_FRAMES = 5  # the frames the service keeps queued: one per heartbeat period of the lease
# [s] between the PC's heartbeats: half the protocol's 0.2 s, so a late one (a loaded machine) still
# keeps the rule; the robot's watchdog allows 1 s. Here, the one small module both processes import.
HEARTBEAT_PERIOD = 0.1
CHUNK = 4096  # bytes read and forwarded at most at once

OPENED, FAILED = b"O", b"E"
WRITE, WRITE_ALONE, QUEUE, DROP = b"W", b"X", b"Q", b"D"
# Each request's head after its kind: its number (echoed in its answer: an answer the service gave up
# waiting for is told from the next one's) and a deadline or lease, on the machine's monotonic clock
# (shared by its processes).
HEAD = struct.Struct("<Hd")
# Each answer: the request's number, status (OK, TIMED_OUT, FAILED_WRITE), frames written whole, writes timed out,
# frames queued now; then the reason of a failed write, UTF-8.
ANSWER = struct.Struct("<HBIIH")
OK, TIMED_OUT, FAILED_WRITE = 0, 1, 2


class Radio:
    """The port, written by one thread (the control loop); its counts for the answers."""

    def __init__(self, port, robot_address: int):
        self.port, self.robot_address = port, robot_address
        self.transmits = TransmitLog()  # frame ids; the service counts the Transmit Statuses it reads
        self.frames_out = self.write_timeouts = 0
        self.queue: collections.deque[bytes] = collections.deque()  # payloads for the cadence, oldest first
        self.lease_until = float("-inf")  # [s] monotonic: the cadence writes nothing after it
        self.last_beat = float("-inf")

    def write(self, payload: bytes, deadline: float) -> tuple[int, str]:
        frame = encode_frame(tx_request(payload, frame_id=self.transmits.next_frame_id(),
                                        destination64=self.robot_address))  # fmt: skip
        try:
            write_within(self.port, frame, min(deadline, time.monotonic() + WRITE_TIMEOUT))
        except serial.SerialTimeoutException:
            self.write_timeouts += 1
            return TIMED_OUT, ""
        except (serial.SerialException, OSError) as error:
            return FAILED_WRITE, str(error)
        self.frames_out += 1
        return OK, ""

    def queue_frame(self, lease_until: float, payload: bytes) -> None:
        """Keep ``payload`` for the cadence, and the service's lease until ``lease_until`` (monotonic)."""
        self.queue.append(payload)
        while len(self.queue) > 2 * LEASE_FRAMES:  # a service faster than the cadence: the oldest go
            self.queue.popleft()
        self.lease_until = max(self.lease_until, lease_until)

    def beat(self, now: float) -> bool:
        """The cadence's frame, written: the oldest queued, while the service's lease holds (whether one went)."""
        if not self.queue or now >= self.lease_until:
            return False
        self.write(self.queue.popleft(), time.monotonic() + WRITE_TIMEOUT)
        self.last_beat = now
        return True

    def answer(self, number: int, status: int, reason: str = "") -> bytes:
        return ANSWER.pack(number, status, self.frames_out, self.write_timeouts, len(self.queue)) + reason.encode()


def forward(port, data: socket.socket, stop: threading.Event) -> None:
    """Every byte read from the port, to the service; the data socket closed when the port fails."""
    data.setblocking(False)  # a stalled service must never stall this process: a full socket drops
    try:
        while not stop.is_set():
            chunk = port.read(port.in_waiting or 1)
            if chunk:
                # A full socket drops the chunk: the service's parser resynchronises on the next frame.
                with contextlib.suppress(BlockingIOError):
                    data.send(chunk)
    except (serial.SerialException, OSError, TypeError):
        pass  # the port failed (TypeError: pyserial's closed socket): the end of file says so
    finally:
        stop.set()
        data.close()


def serve(radio: Radio, control: socket.socket, stop: threading.Event, parent: int) -> None:
    """Answer the service's requests, and keep the cadence between them, until the service goes."""
    due = time.monotonic()
    while not stop.is_set() and os.getppid() == parent:
        now = time.monotonic()
        if now >= due and now - radio.last_beat >= HEARTBEAT_PERIOD * 0.999 and radio.beat(now):
            # Each beat due a period after the last was due; more than a period late, afresh.
            due = due + HEARTBEAT_PERIOD if due + HEARTBEAT_PERIOD > now else now + HEARTBEAT_PERIOD
        wait = max(0.0, due - time.monotonic()) if radio.queue else READ_TIMEOUT * 5
        control.settimeout(wait)
        try:
            request = control.recv(CHUNK)
        except (TimeoutError, BlockingIOError):  # BlockingIOError: a wait of 0 (a beat due now)
            continue
        if not request:
            return  # the service closed its end, or died
        if len(request) < 1 + HEAD.size:
            answer = radio.answer(0, FAILED_WRITE, f"a request of {len(request)} bytes")
        else:
            answer = handle(radio, request)
        try:
            control.sendall(answer)
        except OSError:
            return  # the service closed its end meanwhile


def handle(radio: Radio, request: bytes) -> bytes:
    """Do one request of the service's; its answer."""
    kind, (number, stamp), payload = request[:1], HEAD.unpack_from(request, 1), request[1 + HEAD.size :]
    if kind in (WRITE, WRITE_ALONE):
        if kind == WRITE_ALONE:  # an e-stop: the line is its own from now on
            radio.queue.clear()
        return radio.answer(number, *radio.write(payload, stamp))
    if kind == QUEUE:
        radio.queue_frame(stamp, payload)
        return radio.answer(number, OK)
    if kind == DROP:
        radio.queue.clear()
        return radio.answer(number, OK)
    return radio.answer(number, FAILED_WRITE, f"unknown request {kind!r}")


def main(argv: list[str]) -> int:
    url, baud, robot_address, control_fd, data_fd = argv
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # the service ends this process, after its shutdown
    signal.signal(signal.SIGTERM, signal.SIG_IGN)
    parent = os.getppid()
    control = socket.socket(fileno=int(control_fd))
    data = socket.socket(fileno=int(data_fd))
    try:
        port = open_serial(url, int(baud))
    except (serial.SerialException, ValueError, OSError) as error:
        control.sendall(FAILED + str(error).encode())
        return 1
    control.sendall(OPENED)
    stop = threading.Event()
    reader = threading.Thread(target=forward, args=(port, data, stop), name="radio-reader", daemon=True)
    reader.start()
    try:
        serve(Radio(port, int(robot_address)), control, stop, parent)
    finally:
        stop.set()
        reader.join(1.0)
        port.close()
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
