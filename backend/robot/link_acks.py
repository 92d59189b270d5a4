"""The link's acknowledged commands: each written again until the robot acknowledges it (docs/protocol.md §3).

A command whose acknowledgement is late or lost is written again — the same message, the same
sequence number, so the firmware answers a repeat without applying it twice — every
:data:`COMMAND_RESEND`, until it is acknowledged, the link is lost (the reader heard nothing from
the robot for its heartbeat timeout) or the command's bound passes (the link's heartbeat timeout
and :data:`COMMAND_MARGIN`). Then a :class:`LinkError` names the command, how long it went
unanswered and how many times it was sent, and whether the link was lost.

The e-stop keeps its own rules (:meth:`backend.robot.link.RobotLink.estop`: every 20 ms for 150 ms,
then in place of heartbeats); it only shares the table of acknowledgements awaited.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable

from backend.robot.link_types import LinkError
from backend.robot.messages import Ack, Command, SetLeg

# [s] between the copies of an unacknowledged command. The PC's heartbeat period: a resend costs the
# line no more than the heartbeats already do (a SET_LEG frame is 27 bytes, 5 ms at 57.6 kbaud); it
# is longer than a healthy round trip (under 1 ms to the virtual robot, p99 57 ms through a busy
# service), so a copy is rarely sent for an acknowledgement already on its way, and a needless one is
# harmless (the firmware answers it from memory); and about ten copies fit in the robot's 1 s watchdog.
COMMAND_RESEND = 0.1
# [s] a command's bound beyond the link's heartbeat timeout: a robot gone silent is declared lost by
# the reader first, so the error names the real cause, even when a loaded machine keeps the reader
# from running for a while (e-stops through a saturated service waited up to 0.64 s); a robot that
# talks but never answers is given as long as a silent one, and this margin.
COMMAND_MARGIN = 0.5


def confirm(done: Callable[[], bool], seconds: float, why: Callable[[], str]) -> None:
    """Wait up to ``seconds`` for ``done()`` — the telemetry that shows an acknowledged command's
    effect — polling every millisecond; a LinkError saying ``why()`` if it is not."""
    deadline = time.monotonic() + seconds
    while not done():
        if time.monotonic() > deadline:
            raise LinkError(why())
        time.sleep(0.001)


def describe(message) -> str:
    """A command in an operator's words: ``SET_LEG (right leg, psi0 35.00°, zeta0 0.8800, seq 812)``."""
    if isinstance(message, SetLeg):
        return (
            f"SET_LEG ({message.leg.name.lower()} leg, psi0 {message.psi0_deg:.2f}°, "
            f"zeta0 {message.zeta0:.4f}, seq {message.seq})"
        )
    if isinstance(message, Command):
        return f"{message.kind.name} (seq {message.seq})"
    return repr(message)


class Acknowledgements:
    """The acknowledgements awaited, by sequence number (the reader delivers them: :meth:`heard`),
    the commands' resends (``resends``: copies after the first, written whole or not), and whether a
    copy is being written now (``writing``: the heartbeat thread gives way to it). ``clock`` [s]: the
    time the resends and the bound are reckoned on (the monotonic clock; a test passes its own)."""

    def __init__(self, clock: Callable[[], float] = time.monotonic):
        self._clock = clock
        self._waiting: dict[int, tuple[threading.Event, list[Ack]]] = {}
        self._writing: set[int] = set()  # the seqs of the copies being written (waiting for the port)
        self.resends = 0

    @property
    def writing(self) -> bool:
        return bool(self._writing)

    def expect(self, seq: int) -> tuple[threading.Event, list[Ack]]:
        """Await the acknowledgement of ``seq``: an event set when it is heard, and the list it is put in."""
        entry = (threading.Event(), [])
        self._waiting[seq] = entry
        return entry

    def forget(self, seq: int) -> None:
        self._waiting.pop(seq, None)

    def heard(self, ack: Ack) -> None:
        """The robot acknowledged ``ack.acked`` (an acknowledgement nobody awaits is dropped)."""
        entry = self._waiting.get(ack.acked)
        if entry is not None:
            entry[1].append(ack)
            entry[0].set()

    def send(
        self,
        message,
        write: Callable,
        *,
        bound: float,
        gone: Callable[[], str | None] = lambda: None,
        quiet: Callable[[], bool] = lambda: False,
    ) -> Ack:
        """Write ``message`` (``write(message, deadline)``) and again every COMMAND_RESEND until its
        acknowledgement, which is returned. Raises LinkError once the link is ``gone()`` (its reason)
        or ``bound`` [s] has passed. A failed write (a jammed line: counted by the port) is tried
        again on the next copy. No copy is written while ``quiet()``: the wait goes on."""
        event, box = self.expect(message.seq)
        started = self._clock()
        deadline = started + bound
        sends = failed = 0
        failures: dict[str, None] = {}  # why writes failed, each once, in order
        lost = None
        try:
            due = started
            while True:
                if self._clock() >= due:
                    if not sends or not quiet():
                        if sends:
                            self.resends += 1
                        sends += 1
                        self._writing.add(message.seq)
                        try:
                            write(message, deadline)
                        except LinkError as error:
                            failed += 1
                            failures[str(error)] = None
                        finally:
                            self._writing.discard(message.seq)
                    # Each copy due a period after the last was due; more than a period late (a
                    # blocked write, a late wake-up): the cadence starts afresh.
                    due += COMMAND_RESEND
                    if due <= self._clock():
                        due = self._clock() + COMMAND_RESEND
                if event.wait(max(0.0, min(due, deadline) - self._clock())):
                    return box[0]
                lost = gone()
                if lost is not None or self._clock() >= deadline:
                    break
        finally:
            self.forget(message.seq)
        waited = self._clock() - started
        why = f"no acknowledgement for {describe(message)} in {waited:.2f} s after {sends} sends"
        if failed:
            why += f" ({failed} failed: {'; '.join(failures)})"
        if lost is not None:
            why += f": the link was lost ({lost})"
        raise LinkError(why)
