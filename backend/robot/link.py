"""The PC's side of the robot link: protocol v1 over the radio, heartbeats, and safety.

``RobotLink(url)`` opens its port (:class:`~backend.robot.link_port.LinkPort`: pyserial URLs,
frames whole and bounded). A reader thread decodes frames and tracks the robot's state from its
telemetry and acknowledgements; a heartbeat thread keeps the robot armed. Silence from the robot
for ``heartbeat_timeout`` is a lost link: the state becomes ``disconnected`` and the ``on_lost``
callbacks run (a live run aborts, keeping what it recorded). Leg commands are checked against the servo
limits; commands are resent until acknowledged (:mod:`~backend.robot.link_acks`). Every state change,
and a restart of the robot (:mod:`~backend.robot.link_restarts`), is kept in ``transitions``.

Faults a lab meets are bounded and counted, never raised into a caller's lap: only Receive Packets from
``robot_address`` are heard (another radio's are ``foreign_frames``), and the radio's own Transmit Statuses
are counted but are no sign of the robot's life. :meth:`RobotLink.estop` takes no lock held for longer than
one bounded write, and gives up after its ``timeout`` with an honest :class:`EstopResult`; the heartbeat
thread then sends that ESTOP instead of heartbeats until the robot acknowledges it. The e-stop latch is the
service's (:class:`backend.robot.latch.EstopLatch`): it outlives the link, every connection sends the
latched ESTOP first, ARM and START are refused (:class:`EstopLatched`) and the link stays e-stopped
(:func:`~backend.robot.link_types.telemetry_moves`) until a RESET is acknowledged.
"""

from __future__ import annotations

import contextlib
import random
import threading
import time
from collections.abc import Callable

import serial

from backend.robot.latch import EstopLatch
from backend.robot.limits import ServoLimits
from backend.robot.link_acks import COMMAND_MARGIN, Acknowledgements, confirm, describe
from backend.robot.link_cadence import keep_cadence, top_up
from backend.robot.link_port import WRITE_TIMEOUT, LinkPort
from backend.robot.link_restarts import restart_reason
from backend.robot.link_types import FROM_ROBOT, SAFE, EstopResult, LinkError, LinkState, Transition, telemetry_moves
from backend.robot.messages import Ack, Command, Kind, Leg, ProtocolError, Result, SetLeg, Telemetry, decode
from backend.robot.process_port import ProcessPort
from backend.robot.xbee import ROBOT_ADDRESS, TX_STATUS, FrameError, FrameParser, parse_rx_packet, parse_tx_status

HEARTBEAT_TIMEOUT = 1.0  # [s]
COMMAND_TIMEOUT = 0.5  # [s] for the telemetry showing an acknowledged command's effect
ESTOP_TIMEOUT = 0.15  # [s] an e-stop's whole budget, blocked writes included: the API answers within 200 ms
ESTOP_REPEAT = 0.02  # [s] between e-stop repeats until acknowledged


class EstopLatched(LinkError):
    """ARM or START while the e-stop latch holds: refused until a RESET is acknowledged."""


class RobotLink:
    def __init__(
        self,
        url: str,
        *,
        baud: int = 57_600,
        limits: ServoLimits | None = None,
        heartbeat_timeout: float = HEARTBEAT_TIMEOUT,
        robot_address: int = ROBOT_ADDRESS,
        latch: EstopLatch | None = None,
        radio_process: bool = False,
    ):
        self.url, self.baud, self.robot_address = url, baud, robot_address
        self.limits, self.heartbeat_timeout = limits or ServoLimits(), heartbeat_timeout
        self.state = LinkState.DISCONNECTED
        self.transitions: list[Transition] = []
        self.telemetry: Telemetry | None = None
        self._telemetry_heard = 0  # TELEMETRY frames from the robot (written by the reader only)
        self.parser = FrameParser()
        self.rejected_payloads = 0
        self.foreign_frames = 0  # Receive Packets from a radio that is not robot_address
        self.estops_unacknowledged = 0
        self.estop_repeats = 0  # ESTOPs written again for an e-stop already sent (counted in "retries")
        self.on_lost: list[Callable[[str], None]] = []
        # Frames out, whole and bounded, and their counts; in a radio process of its own, the heartbeats' time too.
        self.port = (ProcessPort if radio_process else LinkPort)(url, baud, robot_address)
        self._seq = random.SystemRandom().randrange(0x10000)  # no new link's seq repeats one the robot recalls (§3)
        self._acks = Acknowledgements()  # awaited, by seq; and the commands' resends
        self.restarts, self.last_restart = 0, None  # the robot's restarts since this link was made; the last's reason
        self._last_telemetry: Telemetry | None = None  # the last heard, on any connection (the reader's)
        self._lock = threading.Lock()
        self._last_heard = 0.0
        self._stop = threading.Event()
        self._threads: list[threading.Thread] = []
        self.send_heartbeats = True  # tests turn this off to starve the robot
        self.latch = latch or EstopLatch()  # the service's: it outlives this link
        # The latched ESTOP that the heartbeat thread sends in place of heartbeats until the robot
        # acknowledges it (None: none), so the robot's own watchdog disarms it even on a lossy line.
        self._pending_estop: Command | None = None
        self._resetting = False  # a RESET is under way (written by reset(), read by the reader)

    # Connection -----------------------------------------------------------------------------
    def connect(self, timeout: float = 3.0) -> LinkState:
        """Open the port and wait for the robot's first telemetry. A held e-stop latch is sent
        first, in place of heartbeats, until the robot acknowledges it on this connection."""
        self.telemetry = None
        self.parser = FrameParser()
        self._forget_estop()
        self._estop_first()  # the robot may have restarted, or never heard it
        self.port.open()
        self._stop.clear()
        self._last_heard = time.monotonic()
        self._threads = [
            threading.Thread(target=self._read_loop, name="robot-link-reader", daemon=True),
            threading.Thread(target=self._heartbeat_loop, name="robot-link-heartbeat", daemon=True),
        ]
        for thread in self._threads:
            thread.start()
        try:
            confirm(lambda: self.telemetry is not None, timeout,
                    lambda: f"no telemetry from the robot at {self.url} within {timeout:g} s")  # fmt: skip
        except LinkError:
            self.close()
            raise
        return self.state

    def reconnect(self, timeout: float = 1.0) -> LinkState:
        """Close what is left of a dropped link and connect again (the robot stays as it decided:
        after silence it has disarmed itself). In the service only the link's supervisor calls
        this, ``connect`` and ``close``: one thread at a time."""
        self.close()
        return self.connect(timeout)

    def close(self) -> None:
        self._stop.set()
        for thread in self._threads:
            if thread is not threading.current_thread():
                thread.join(2)
        self.port.close()
        self._move(LinkState.DISCONNECTED, "closed")

    # Commands -------------------------------------------------------------------------------
    def arm(self) -> None:
        self._refuse_if_latched("arm")
        self._command(Command(self._next_seq(), Kind.ARM), expect=LinkState.ARMED)

    def start(self) -> None:
        """Armed robot: launch and keep jumping with the legs' current controls."""
        self._refuse_if_latched("start")
        self._command(Command(self._next_seq(), Kind.START), expect=LinkState.RUNNING)

    def disarm(self) -> None:
        self._command(Command(self._next_seq(), Kind.DISARM), expect=LinkState.DISARMED)

    def make_safe(self) -> LinkState:
        """Every ending's DISARM: sent whatever the link believes (a stale or forged TELEMETRY may
        say disarmed while the robot runs), then confirmed by telemetry received after the robot's
        acknowledgement. Returns the confirmed state: disarmed, or e-stopped (an e-stopped robot
        refuses DISARM and is as safe); raises LinkError if neither is confirmed in time."""
        if self.state == LinkState.DISCONNECTED:
            raise LinkError("the link is down: the robot's watchdog disarms it")
        ack = self._acknowledged(Command(self._next_seq(), Kind.DISARM))
        heard = self._telemetry_heard  # telemetry counted from here on was sent after the DISARM's ack
        confirm(lambda: self._telemetry_heard != heard and self.telemetry.state in SAFE, COMMAND_TIMEOUT,
                lambda: f"DISARM answered {ack.result.name.lower()} but no telemetry confirms it")  # fmt: skip
        return FROM_ROBOT[self.telemetry.state]

    def reset(self) -> None:
        """Clear an e-stop (to disarmed) and release the latch once the robot confirms it. Repeats of an
        unacknowledged ESTOP stop before the RESET is sent (none may follow it), and resume if it is not confirmed."""
        with self.port.write_lock:  # not between the heartbeat thread's pick of a repeat and its write
            pending = self._forget_estop()
            if self.port.keeps_time:  # the repeats queued in the radio process too (gone with it if it ended),
                with contextlib.suppress(LinkError):  # and heartbeats queued in their place at once
                    self.port.drop_queued()
                    top_up(self.port, self._cadence_frame)
        self._resetting = True  # the robot's telemetry may now take the link out of e-stopped
        try:
            self._command(Command(self._next_seq(), Kind.RESET), expect=LinkState.DISARMED)
        except LinkError:
            with self._lock:
                if self._pending_estop is None:
                    self._pending_estop = pending
            if pending is not None and self.port.keeps_time:  # its repeats go next, not the heartbeats queued
                with contextlib.suppress(LinkError):
                    self.port.drop_queued()
            raise
        finally:
            self._resetting = False
        self.latch.release()

    def set_leg(self, leg: Leg, psi0_deg: float, zeta0: float) -> None:
        """Send a leg's controls for its next touchdown; outside the servo limits, refuse to send."""
        self.limits.check(psi0_deg, zeta0)
        self._command(SetLeg(self._next_seq(), leg, psi0_deg, zeta0))

    estop_timeout = ESTOP_TIMEOUT  # [s] estop()'s default; a test of reaching, not of speed, widens it

    def estop(self, timeout: float | None = None) -> EstopResult:
        """Emergency stop: repeat ESTOP every ESTOP_REPEAT until acknowledged or ``timeout`` [s] (or estop_timeout).

        Tried whatever the link believes (a link seen as lost may still reach the robot), and never
        raises: a blocked or closed port only ends the attempt sooner. Not acknowledged, the
        heartbeats stop, so the robot's own watchdog disarms it within its heartbeat timeout, and
        the heartbeat thread repeats this ESTOP every HEARTBEAT_PERIOD until it is acknowledged
        (then the link is e-stopped) or a reset. Either way the latch holds until a reset."""
        timeout = self.estop_timeout if timeout is None else timeout
        started = time.monotonic()
        deadline = started + timeout
        write_by = deadline - WRITE_TIMEOUT  # a write started by then ends, even blocked, by the deadline
        message = Command(self._next_seq(), Kind.ESTOP)
        event, _box = self._acks.expect(message.seq)
        reason = None
        self._forget_estop()  # this e-stop supersedes one still repeated in the background
        self.latch.engage()  # the line is the e-stop's; heartbeats resume only once acknowledged
        tries = 0
        try:
            while not event.is_set() and time.monotonic() < deadline:
                if time.monotonic() < write_by:
                    if tries:
                        self.estop_repeats += 1
                    tries += 1
                    try:  # the heartbeats queued in a radio process go: the line is the e-stop's
                        self.port.write(message, write_by, clear_queue=True)
                    except LinkError as error:
                        reason = str(error)
                        if not self.port.is_open:
                            break  # closed: nothing to retry on
                event.wait(min(ESTOP_REPEAT, max(0.0, deadline - time.monotonic())))
        finally:
            self._acks.forget(message.seq)
        latency = time.monotonic() - started
        if event.is_set():
            self.latch.acknowledged()
            self._move(LinkState.ESTOPPED, "e-stop acknowledged")
            return EstopResult(True, latency)
        self.estops_unacknowledged += 1
        # The heartbeat thread repeats it; its acknowledgement, whenever heard, e-stops the link.
        self._pending_estop = message
        why = f"no acknowledgement within {timeout * 1000:.0f} ms" + (f" ({reason})" if reason else "")
        return EstopResult(False, latency, why)

    @property
    def last_delivery_failure(self) -> str | None:
        """The last Transmit Status that said not delivered, by name and code, or None."""
        return self.port.transmits.last_failure

    @property
    def write_timeouts(self) -> int:
        return self.port.write_timeouts

    def counters(self) -> dict[str, int]:
        """Counts since the last connect (the parser's, ``frames_in`` to ``garbage_bytes``) and since
        this link was made (the rest). ``frames_out``: Transmit Requests written whole;
        ``transmit_status``: Transmit Statuses heard, ``delivery_failures`` of them not delivered
        (the last: :attr:`last_delivery_failure`); ``retries``: the radio's retries as its
        statuses report them plus the link's ESTOP repeats (in :meth:`estop` and the background);
        ``command_resends``: the other commands' copies after the first (:mod:`~backend.robot.link_acks`)."""
        stats = self.parser.stats
        return {
            "frames_in": stats.frames,
            "bad_checksum": stats.bad_checksum,
            "truncated": stats.truncated,
            "bad_length": stats.bad_length,
            "garbage_bytes": stats.garbage_bytes,
            "rejected_payloads": self.rejected_payloads,
            "foreign_frames": self.foreign_frames,
            "write_timeouts": self.port.write_timeouts,
            "estops_unacknowledged": self.estops_unacknowledged,
            "frames_out": self.port.frames_out,
            "transmit_status": self.port.transmits.statuses,
            "delivery_failures": self.port.transmits.failures,
            "retries": self.port.transmits.retries + self.estop_repeats,
            "command_resends": self._acks.resends,
        }

    # Internals ------------------------------------------------------------------------------
    def _refuse_if_latched(self, name: str) -> None:
        # As the firmware latches an e-stop, the PC latches it too: a robot that restarted, or never
        # heard the ESTOP, would otherwise arm.
        if self.latch.held:
            raise EstopLatched(f"the e-stop latch holds ({self.latch.state.reason()}); reset before you {name}")

    def _command(self, message, expect: LinkState | None = None) -> Ack:
        """Send, wait for the acknowledgement, and (``expect``) for the telemetry showing its effect."""
        if self.state == LinkState.DISCONNECTED:
            raise LinkError("the link is down; connect first")
        ack = self._acknowledged(message)
        if ack.result != Result.OK:
            raise LinkError(f"the robot refused {describe(message)}: {ack.result.name.lower()}")
        if expect is not None:  # and the telemetry that shows its effect
            why = f"{message.kind.name} acknowledged but the robot reports {{}}, not {expect.value}"
            confirm(lambda: self.state == expect, COMMAND_TIMEOUT, lambda: why.format(self.state.value))
        return ack

    def _acknowledged(self, message) -> Ack:
        """Send ``message`` until the robot acknowledges it, the link is lost (the reason it went: a
        command is sent only on a link that was up) or its bound passes. No copy goes while an
        unacknowledged ESTOP owns the line: it would feed the robot's watchdog instead."""
        return self._acks.send(
            message, self.port.write, bound=self.heartbeat_timeout + COMMAND_MARGIN,
            quiet=lambda: self.latch.state.pending,
            gone=lambda: self.transitions[-1].reason if self.state == LinkState.DISCONNECTED else None,
        )  # fmt: skip

    def _next_seq(self) -> int:
        with self._lock:
            self._seq = (self._seq + 1) & 0xFFFF
            return self._seq

    def _read_loop(self) -> None:
        while not self._stop.is_set():
            try:
                chunk = self.port.read()
            except (serial.SerialException, OSError):
                self._lost("read failed")
                return
            for data in self.parser.feed(chunk):
                try:
                    if data[0] == TX_STATUS:
                        # The PC's own radio on a frame it sent: not the robot's voice or heartbeat.
                        self.port.transmits.heard(parse_tx_status(data))
                        continue
                    packet = parse_rx_packet(data)
                    if packet.source64 != self.robot_address:
                        self.foreign_frames += 1  # another radio: never our robot's state or heartbeat
                        continue
                    message = decode(packet.payload)
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
            self._acks.heard(message)
            if self._pending_estop is not None:
                self._estop_acknowledged(message.acked)
        elif isinstance(message, Telemetry):
            restart = restart_reason(self._last_telemetry, message)
            self._last_telemetry = self.telemetry = message
            self._telemetry_heard += 1
            state = FROM_ROBOT[message.state]
            if restart is not None:  # counted before the state moves (a run sees both at once), and
                self._restarted(restart)  # recorded even where the latch holds the link's state
            moves = telemetry_moves(self.state, state, latched=self.latch.held, resetting=self._resetting)
            if moves or restart is not None:
                self._move(state if moves else self.state, restart or "telemetry", always=restart is not None)

    def _restarted(self, reason: str) -> None:
        self.restarts, self.last_restart = self.restarts + 1, reason
        self._estop_first()  # it forgot its e-stop: e-stopped again before anything else

    def _estop_first(self) -> None:
        """Under a held latch, the ESTOP goes in place of heartbeats until the robot acknowledges it."""
        if self.latch.held:
            self.latch.unconfirmed()
            estop = Command(self._next_seq(), Kind.ESTOP)
            with self._lock:
                self._pending_estop = estop

    def _heartbeat_loop(self) -> None:
        # An unacknowledged ESTOP goes instead of the heartbeat, so a line that clears still
        # delivers the stop. Any frame feeds the firmware's watchdog, ESTOP too; that keeps no
        # robot going: ESTOP latches it e-stopped, which only RESET leaves.
        keep_cadence(self.port, self._stop, self._cadence_frame)

    def _cadence_frame(self) -> Command | None:
        """The next frame of the heartbeat's cadence: the unacknowledged ESTOP's copy, a heartbeat,
        or None — none while an e-stop is under way, tests starve the robot, or a command's copy
        waits for the port (it is a frame too, or a blocked line would starve it)."""
        message = self._pending_estop
        if message is not None:
            self.estop_repeats += 1
        elif self.send_heartbeats and not self.latch.state.pending and not self._acks.writing:
            message = Command(self._next_seq(), Kind.HEARTBEAT)
        return message

    def _forget_estop(self) -> Command | None:
        """Stop repeating the pending e-stop: returns it, or None."""
        with self._lock:
            pending, self._pending_estop = self._pending_estop, None
        return pending

    def _estop_acknowledged(self, seq: int) -> None:
        # The reader heard the robot acknowledge the pending ESTOP: as estop() on an acknowledgement.
        with self._lock:
            if self._pending_estop is None or self._pending_estop.seq != seq:
                return  # reset, superseded or reconnected meanwhile
            self._pending_estop = None
        self.latch.acknowledged()
        self._move(LinkState.ESTOPPED, "e-stop acknowledged (repeated)")

    def _lost(self, reason: str) -> None:
        self._stop.set()
        self._move(LinkState.DISCONNECTED, reason)
        for callback in list(self.on_lost):
            callback(reason)

    def _move(self, state: LinkState, reason: str, *, always: bool = False) -> None:  # always: even unchanged
        with self._lock:
            if state == self.state and not always:
                return
            self.transitions.append(Transition(time.time(), self.state, state, reason))
            self.state = state
