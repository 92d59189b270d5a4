"""A fault rig for the robot link: on a pty (``os.openpty``, no extra binaries), and a flapping radio.

The link opens :attr:`PtyRobot.path` (or the stable symlink :attr:`PtyRobot.by_id`, as a lab opens
``/dev/serial/by-id/…``) as it would a USB radio. The rig plays a robot in one of two ways:

- talking only (the default): TELEMETRY in ``state`` from ``source64`` every ``period``, and it never
  reads what the PC sends, so the PC→robot direction fills and then blocks;
- answering (``firmware=``): the robot's firmware (:class:`backend.robot.firmware.Firmware`) behind
  the line, as the virtual robot runs it — it reads the PC's frames, acknowledges, keeps its
  watchdog and sends its own heartbeats and telemetry; :attr:`PtyRobot.received` keeps what it got;
- playing both radios (``answers=True``): talking as above (while :attr:`~PtyRobot.talking`), and each
  Transmit Request is answered with a Transmit Status (:attr:`~PtyRobot.delivery_status`,
  :attr:`~PtyRobot.retry_count`) and, delivered, goes to the firmware's rules without their
  watchdog, which reply and may change ``state``; it keeps what the PC put on the line
  (:attr:`~PtyRobot.sent`, :attr:`~PtyRobot.frame_ids`) and what the robot got (:attr:`~PtyRobot.heard`).

An answering rig's radio sends a Transmit Status for every frame with a non-zero frame id, as an
XBee does.

Faults, each on demand: :meth:`PtyRobot.jam` fills the PC→robot direction at once (every write
blocks; :meth:`~PtyRobot.unjam` reads again); :meth:`~PtyRobot.go_silent` and
:meth:`~PtyRobot.resume` take the robot out of range and back (nothing arrives either way, the
robot's watchdog runs on); :meth:`~PtyRobot.hang_up` and :meth:`~PtyRobot.plug_in` unplug the radio
(the pty goes away, reads and writes fail, the by-id link disappears) and plug a new one in (a new
pty behind the same by-id link); :meth:`~PtyRobot.flood` interleaves line noise — random bytes,
broken frames, payloads that are no message — with good frames at many times a 57.6 kbaud line's
rate, and counts exactly what the link's parser must see.

:class:`Radio` flaps one TCP address between the virtual robot, nothing, a silent radio and one that
hangs up; :class:`LinkCalls` watches who opens and closes a :class:`RobotLink`, and how many at once;
:func:`flap_supervised` drives a supervised link through a flapping radio and checks what it leaves.
"""

from __future__ import annotations

import contextlib
import fcntl
import logging
import os
import random
import select
import shutil
import socket
import struct
import tempfile
import threading
import time
import tty
from dataclasses import dataclass

from backend.robot.firmware import Firmware
from backend.robot.link import LinkState, RobotLink
from backend.robot.messages import Command, Kind, RobotState, SetLeg, Telemetry, decode, encode
from backend.robot.supervisor import LinkSupervisor
from backend.robot.virtual import VirtualRobot
from backend.robot.xbee import (
    DELIVERED,
    ROBOT_ADDRESS,
    START,
    FrameError,
    FrameParser,
    checksum,
    encode_frame,
    escape,
    parse_tx_request,
    rx_packet,
    tx_status,
)
from tests.helpers import answer_within, free_port

JAM_CHUNK = 4096  # [bytes]
JAM_SETTLE = 3  # fills in a row that find no room
PHASE_S = (0.2, 1.5)  # [s] each phase of the flapping radio lasts between these
TICK = 0.02  # [s] the answering robot's watchdog and telemetry resolution (the virtual robot's)
REQUEST_S = 2.0  # [s] the rig's own thread carries out a hang-up or plug-in within this
FLOOD_RATE = 100_000  # [bytes/s] of line noise: 17 times what a 57.6 kbaud line carries
FLOOD_GARBAGE = (16, 256)  # [bytes] of random bytes per burst, between these
JUNK_PAYLOAD = b"\xee\x00\x00\x01"  # a Receive Packet from the robot whose payload is no message (version 0xEE)
FOREIGN = 0x0013A200DEADBEEF  # another XBee in range


def received_frame(message, *, source64: int = ROBOT_ADDRESS) -> bytes:
    """The bytes the PC's radio delivers for ``message`` sent by the radio ``source64``."""
    return encode_frame(rx_packet(encode(message), source64=source64))


def telemetry(seq: int, state: RobotState) -> Telemetry:
    return Telemetry(seq, state, (30.0, 30.0), (0.9, 0.9), 7400, 0)


@dataclass
class Flood:
    """What a flood put on the line: exactly what the link's parser counts, if it misses nothing.

    Every burst is random bytes (never a start byte, so all outside any frame), a frame with a bad
    checksum, a start byte with an impossible length, a frame from the robot whose payload is no
    message, a TELEMETRY(disarmed) from another radio (:data:`FOREIGN`), a frame cut short by the
    next start byte, and one good TELEMETRY frame in the robot's state; the frames with a bad
    checksum or cut short carry a forged TELEMETRY(disarmed) too."""

    bursts: int = 0
    bytes: int = 0
    garbage_bytes: int = 0
    bad_checksum: int = 0
    bad_length: int = 0
    truncated: int = 0
    rejected_payloads: int = 0
    foreign_frames: int = 0
    good_frames: int = 0
    seconds: float = 0.0


class PtyRobot:
    def __init__(
        self,
        state: RobotState = RobotState.ARMED,
        *,
        source64: int = ROBOT_ADDRESS,
        period: float = 0.05,
        firmware: Firmware | None = None,
        answers: bool = False,
        line: str = "pty",
    ):
        """Talking only, in ``state`` every ``period`` [s]; or, given ``firmware``, answering as it
        decides (``state`` and ``period`` are then the firmware's own); or ``answers``: talking, and
        both radios answering by the firmware's rules (no watchdog).

        ``line``: ``"pty"`` (:attr:`path`, :attr:`by_id`), or ``"socket"``: a TCP line on a port of
        its own (:attr:`url`, ``socket://127.0.0.1:PORT``, bound here to port 0), for tests that need
        no serial device. A pty is ``/dev/pts/N``, a name the kernel hands out again at once and that
        any program may open: another service still retrying a ``/dev/pts/N`` that was its robot's
        reads part of this rig's frames and writes its own (issue 40). A socket line's robot hears one
        PC at a time: a new connection replaces the old, as a radio answers whoever sends; jam,
        hang-up and plug-in are the pty's only."""
        assert line in ("pty", "socket"), line
        self.state, self.source64, self.period = state, source64, period
        self.firmware = firmware
        self.answers = answers
        self.talking = True  # talking modes: TELEMETRY goes out
        self.delivery_status = DELIVERED  # what the Transmit Statuses report (0x24, 0x21: not delivered)
        self.retry_count = 0  # the retries they report
        self.sent: list = []  # answers=True: the messages the PC put on the line, delivered or not, in order
        self.frame_ids: list[int] = []  # theirs
        self.heard: list = []  # those delivered to the robot
        self._rules = Firmware()  # answers=True: the firmware's rules, its state set from ``state``
        self.received: list[tuple[float, object]] = []  # (monotonic time, message) the firmware got, heartbeats aside
        self._dir = tempfile.mkdtemp(prefix="pty-robot-")
        self.by_id = os.path.join(self._dir, "usb-XBee_rig-if00-port0")  # as /dev/serial/by-id/… names a radio
        self.master = self._slave = None
        self._listener = self._connection = None  # a socket line's
        if line == "pty":
            self._open()
            self.url = self.path
        else:
            self.path = self.by_id = None
            self._listener = socket.create_server(("127.0.0.1", 0))
            self.url = f"socket://127.0.0.1:{self._listener.getsockname()[1]}"
        self._line = threading.Lock()  # whole frames on the line, and the pty's fds swapped only under it
        self._firmware_lock = threading.Lock()  # the firmware is shared by the rig's thread and a flood
        self._silent = False  # out of range: nothing arrives either way
        self._deaf = False  # jammed: the robot reads nothing
        self._requests: list[tuple[str, threading.Event]] = []
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name="pty-robot", daemon=True)
        self._flood_stop = threading.Event()
        self._flood_thread: threading.Thread | None = None
        self._flood: Flood | None = None

    def start(self) -> PtyRobot:
        self._thread.start()
        return self

    def stop(self) -> None:
        self.stop_flood()
        self._stop.set()
        self._thread.join(2)
        with self._line:
            self._close()
        if self._listener is not None:
            self._listener.close()
        shutil.rmtree(self._dir, ignore_errors=True)

    # Faults ------------------------------------------------------------------------------------
    def jam(self) -> int:
        """Fill the PC→robot buffer (nobody reads it): every write on the line now blocks. Returns
        the bytes it took."""
        assert self._listener is None, "a pty's fault"
        self._deaf = True  # an answering robot stops reading too
        time.sleep(2 * TICK)  # a read under way ends
        flags = fcntl.fcntl(self._slave, fcntl.F_GETFL)
        fcntl.fcntl(self._slave, fcntl.F_SETFL, flags | os.O_NONBLOCK)
        filled = 0
        # Big chunks first, then ever smaller ones: the pty may refuse a chunk while it still has
        # room for a frame, and then the PC's frames would go through.
        for chunk in (JAM_CHUNK, 64, 1):
            settled = 0
            while settled < JAM_SETTLE:  # the kernel moves buffered bytes on to the line discipline's buffer
                before = filled
                with contextlib.suppress(BlockingIOError):
                    while True:
                        filled += os.write(self._slave, b"\0" * chunk)
                settled = settled + 1 if filled == before else 0
                time.sleep(0.01)
        return filled

    def unjam(self) -> None:
        """An answering rig reads again: the jam's bytes, then whatever the PC got onto the line."""
        self._deaf = False

    def go_silent(self) -> None:
        """Out of range: the robot's frames stop arriving and the PC's are lost (read and dropped,
        as a radio transmits into the void); the robot's watchdog runs on."""
        self._silent = True

    def resume(self) -> None:
        """Back in range: frames flow both ways again, on the same line."""
        self._silent = False

    def hang_up(self) -> None:
        """Unplug the PC's radio: the pty is closed (the link's reads and writes fail) and the
        by-id link removed, as udev removes it; the robot itself runs on."""
        self._ask("hang_up")

    def plug_in(self) -> None:
        """Plug a radio in again: a new pty, the by-id link pointing at it (:attr:`path` changes)."""
        self._ask("plug_in")

    def flood(self, rate: float = FLOOD_RATE, *, seed: int = 1) -> Flood:
        """Start line noise at ``rate`` [bytes/s], interleaved whole with the robot's frames, until
        :meth:`stop_flood`; the returned :class:`Flood` fills in as it goes."""
        assert self._flood_thread is None, "one flood at a time"
        self._flood, self._flood_stop = Flood(), threading.Event()
        self._flood_thread = threading.Thread(
            target=self._flooding, args=(self._flood, rate, random.Random(seed)), name="pty-robot-flood", daemon=True
        )
        self._flood_thread.start()
        return self._flood

    def stop_flood(self) -> Flood | None:
        if self._flood_thread is not None:
            self._flood_stop.set()
            self._flood_thread.join(2)
            self._flood_thread = None
        return self._flood

    def commands(self, since: float = 0.0) -> list[Kind]:
        """Every command the robot received after ``since`` (monotonic), in order, heartbeats aside:
        ARM, DISARM, ESTOP … and SET_LEG."""
        kinds = [
            Kind.SET_LEG if isinstance(m, SetLeg) else getattr(m, "kind", None)
            for t, m in list(self.received)
            if t > since
        ]
        return [kind for kind in kinds if kind is not None]

    # The rig's thread ----------------------------------------------------------------------------
    def _open(self) -> None:
        self.master, self._slave = os.openpty()
        tty.setraw(self._slave)  # no line discipline between the frames and the link
        self.path = os.ttyname(self._slave)
        with contextlib.suppress(FileNotFoundError):
            os.unlink(self.by_id)
        os.symlink(self.path, self.by_id)

    def _close(self) -> None:
        if self._listener is not None:  # a socket line: the PC's connection, if any
            if self._connection is not None:
                self._connection.close()
            self._connection = self.master = None
            return
        with contextlib.suppress(FileNotFoundError):
            os.unlink(self.by_id)
        for fd in (self.master, self._slave):
            if fd is not None:
                with contextlib.suppress(OSError):
                    os.close(fd)
        self.master = self._slave = None

    def _answer(self) -> None:
        """A socket line: a PC that connects is the one the robot hears from now on."""
        if select.select([self._listener], [], [], 0)[0]:
            connection, _ = self._listener.accept()
            with self._line:
                self._close()
                self._connection, self.master = connection, connection.fileno()

    def _ask(self, what: str) -> None:
        assert self._listener is None, "a pty's fault"
        done = threading.Event()
        self._requests.append((what, done))
        assert done.wait(REQUEST_S), f"the rig did not {what} within {REQUEST_S:g} s"

    def _serve_requests(self, parser: FrameParser) -> FrameParser:
        # Only this thread reads the pty, so closing or replacing it here never pulls an fd from under a read.
        while self._requests:
            what, done = self._requests.pop(0)
            with self._line:
                if what == "hang_up":
                    self._close()
                elif self.master is None:
                    self._open()
                    parser = FrameParser()
            done.set()
        return parser

    def _run(self) -> None:
        parser, seq, next_talk = FrameParser(), 0, time.monotonic()
        reads = self.firmware is not None or self.answers
        while not self._stop.is_set():
            parser = self._serve_requests(parser)
            if self._listener is not None:
                self._answer()
            master = self.master
            if not reads or master is None or self._deaf:
                time.sleep(TICK if reads else max(0.0, min(TICK, next_talk - time.monotonic())))
            elif select.select([master], [], [], TICK)[0]:
                try:
                    chunk = os.read(master, 4096)
                except OSError:
                    chunk = b""
                if not chunk and self._connection is not None:  # the PC closed the link
                    with self._line:
                        self._close()
                    parser = FrameParser()
                if not self._silent:
                    for data in parser.feed(chunk):
                        self._hear(data)
            if self.firmware is not None:
                with self._firmware_lock:
                    self._send(self.firmware.tick(time.monotonic()))
            elif time.monotonic() >= next_talk:
                next_talk = time.monotonic() + self.period
                seq = (seq + 1) & 0xFFFF
                if self.talking:
                    self._send([telemetry(seq, self.state)])

    def _hear(self, data: bytes) -> None:
        try:
            frame_id, _destination, payload = parse_tx_request(data)
            message = decode(payload)
        except (FrameError, ValueError):
            return
        if frame_id:  # the PC's radio reports delivery, as an XBee does
            self._write(encode_frame(tx_status(frame_id, delivery=self.delivery_status, retries=self.retry_count)))
        if self.answers:
            self._radio(frame_id, message)
            return
        if not (isinstance(message, Command) and message.kind == Kind.HEARTBEAT):
            self.received.append((time.monotonic(), message))
        with self._firmware_lock:
            self._send(self.firmware.receive(message, time.monotonic()))

    def _radio(self, frame_id: int, message) -> None:
        """answers=True: noted, and if delivered, answered by the firmware's rules from ``state``."""
        self.sent.append(message)
        self.frame_ids.append(frame_id)
        if self.delivery_status != DELIVERED:
            return  # lost on the air: the robot never hears it
        self.heard.append(message)
        self._rules.state = self.state
        replies = self._rules.receive(message, time.monotonic())
        self.state = self._rules.state
        self._send(replies)

    def _send(self, messages: list) -> None:
        if messages:
            self._write(b"".join(received_frame(message, source64=self.source64) for message in messages))

    def _write(self, data: bytes) -> bool:
        """Whole on the line unless silent or unplugged; a full line blocks the writer, as a UART does."""
        with self._line:
            if self._silent or self.master is None:
                return False
            try:
                os.write(self.master, data)
            except OSError:
                return False
            return True

    # Line noise ----------------------------------------------------------------------------------
    def _good_telemetry(self) -> Telemetry:
        if self.firmware is None:
            return telemetry(0, self.state)
        with self._firmware_lock:
            return self.firmware.telemetry()

    def _burst(self, generator: random.Random) -> tuple[bytes, dict]:
        garbage = generator.randbytes(generator.randint(*FLOOD_GARBAGE)).replace(bytes((START,)), b"")
        forged = rx_packet(encode(telemetry(generator.getrandbits(16), RobotState.DISARMED)), source64=self.source64)
        body = struct.pack(">H", len(forged)) + forged
        bad_checksum = bytes((START,)) + escape(body + bytes(((checksum(forged) + 1) & 0xFF,)))
        bad_length = bytes((START, 0xFF, 0xFF))  # 65535 bytes: impossible, the parser gives up on it at once
        junk = encode_frame(rx_packet(JUNK_PAYLOAD, source64=self.source64))
        foreign = received_frame(telemetry(generator.getrandbits(16), RobotState.DISARMED), source64=FOREIGN)
        cut_short = bytes((START,)) + escape(body[: len(body) // 2])  # the good frame's start byte ends it
        good = received_frame(self._good_telemetry(), source64=self.source64)
        counts = {"garbage_bytes": len(garbage), "bad_checksum": 1, "bad_length": 1, "rejected_payloads": 1,
                  "foreign_frames": 1, "truncated": 1, "good_frames": 1}  # fmt: skip
        return garbage + bad_checksum + bad_length + junk + foreign + cut_short + good, counts

    def _flooding(self, flood: Flood, rate: float, generator: random.Random) -> None:
        started = time.monotonic()
        while not self._flood_stop.is_set():
            data, counts = self._burst(generator)
            if self._write(data):  # one burst whole: the robot's own frames go between bursts
                flood.bursts += 1
                flood.bytes += len(data)
                for name, count in counts.items():
                    setattr(flood, name, getattr(flood, name) + count)
            # Pace to the rate: sleep off the bytes sent ahead of it.
            ahead = flood.bytes / rate - (time.monotonic() - started)
            if ahead > 0:
                self._flood_stop.wait(ahead)
            flood.seconds = time.monotonic() - started


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


THREADS_SPARE = 3  # threads above the baseline once the flapping ends (pytest's, logging's: not ours)
THREADS_DURING = 8  # at most this many above the baseline while it flaps: supervisor, link, robot, rig
BACK_WITHIN_S = 10.0  # [s] "comes back instead of never": generous, not a latency claim
ANSWER_BOUND_S = 20.0  # [s] a request answers instead of hanging (a bounded connect and closes fit in it)
LINK_THREADS = ["robot-link-heartbeat", "robot-link-reader", "robot-link-supervisor"]  # a live supervised link's


def wait_for(predicate, what: str, timeout: float = BACK_WITHIN_S) -> None:
    deadline = time.monotonic() + timeout
    while not predicate():
        assert time.monotonic() < deadline, f"{what} within {timeout:g} s"
        time.sleep(0.02)


def link_threads() -> list[str]:
    """The names of the live threads a robot link or its supervisor runs, sorted."""
    return sorted(thread.name for thread in threading.enumerate() if thread.name.startswith("robot-link-"))


def flap_supervised(seconds: float, monkeypatch, caplog, thread_errors: list, *, seed: int = 7) -> dict:
    """Connect through a supervisor, flap the radio for ``seconds``, end with the robot up, then shut
    down; checks what the supervisor promises and returns what was seen.

    Checked: nothing logged at WARNING or above (any logger) and no exception escaped a thread; one
    connect at a time, all by the supervisor's thread; at most THREADS_DURING threads above the
    baseline while it flaps; once the robot is back, exactly the live link's threads named
    ``robot-link-*`` (none left from an earlier attempt); after shutdown none, and the thread count
    back within THREADS_SPARE of the baseline. ``thread_errors``: where ``threading.excepthook``
    puts what escapes a thread."""
    caplog.set_level(logging.DEBUG, logger="parkourlab.robot")
    calls = LinkCalls(monkeypatch)
    baseline = threading.active_count()
    radio = Radio(seed)
    robot = VirtualRobot("127.0.0.1", radio.port).start()
    supervisor = LinkSupervisor()
    link = RobotLink(radio.url)
    assert answer_within(ANSWER_BOUND_S, supervisor.connect, link) == LinkState.DISARMED
    robot.stop()
    radio.flap(seconds)
    most_threads = baseline
    while radio.flapping:
        most_threads = max(most_threads, threading.active_count())
        time.sleep(0.01)
    radio.join()
    robot = VirtualRobot("127.0.0.1", radio.port).start()  # the robot is back for good
    try:
        wait_for(lambda: link.state == LinkState.DISARMED, "the link is back once the robot is")
        back_threads = link_threads()
        answer_within(ANSWER_BOUND_S, supervisor.close)
    finally:
        robot.stop()
    seen = {
        "baseline": baseline,
        "most": most_threads,
        "after": None,
        "phases": radio.phases,
        "reconnects": supervisor.reconnects,
        "connects": calls.connects,
        "link_threads_back": back_threads,
    }
    with contextlib.suppress(AssertionError):
        wait_for(lambda: threading.active_count() <= baseline + THREADS_SPARE, "the threads back to the baseline")
    seen["after"] = threading.active_count()
    errors = [r for r in caplog.records if r.levelno >= logging.WARNING or r.exc_info]
    assert errors == [] and thread_errors == [], (errors, thread_errors)
    assert seen["after"] <= baseline + THREADS_SPARE, f"threads not back to the baseline (+{THREADS_SPARE}): {seen}"
    assert back_threads == LINK_THREADS, f"robot-link-* threads beyond the live link's: {seen}"
    assert link_threads() == [], f"robot-link-* threads left after shutdown: {link_threads()}"
    assert calls.most_connecting == 1, "two connects of one link at once"
    assert calls.callers == {"robot-link-supervisor"}, f"only the supervisor opens and closes: {calls.callers}"
    assert most_threads <= baseline + THREADS_DURING, f"too many threads while flapping: {seen}"
    assert supervisor.link is None and link.state == LinkState.DISCONNECTED
    return seen


def climb_open_loop(robot, legs: dict, jumps: int, timeout: float = 30.0):
    """Connect to the started virtual ``robot`` as the PC does, set ``legs`` ({Leg: (psi0_deg, zeta0)}),
    arm and start; wait for ``jumps`` jumps or the run's end; disarm; close the link. Returns the
    link's state when the wait ended (RUNNING: the jumps were done) and the closed link (its last
    telemetry)."""
    from backend.robot.link import LinkState, RobotLink

    link = RobotLink(robot.url)
    try:
        link.connect()
        for leg, (psi0, zeta0) in legs.items():
            link.set_leg(leg, psi0, zeta0)
        link.arm()
        link.start()
        deadline = time.monotonic() + timeout
        while robot.climber.jumps < jumps and link.state == LinkState.RUNNING:
            assert time.monotonic() < deadline, "the robot stopped climbing"
            time.sleep(0.02)
        state_at_end = link.state
        if state_at_end == LinkState.RUNNING:
            link.disarm()
        time.sleep(0.05)
        return state_at_end, link
    finally:
        link.close()
