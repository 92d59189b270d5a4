"""The heartbeat's cadence on the PC's side: one frame every HEARTBEAT_PERIOD, on time.

:func:`keep_cadence` runs on the link's heartbeat thread. Each frame is due a period after the
previous one was due, not after it was written: a late wake-up shortens the next wait instead of
pushing every later heartbeat back. On the in-process port it writes each frame; on a
:class:`~backend.robot.process_port.ProcessPort` (``keeps_time``) it only keeps the radio process'
queue full — one frame each period, which renews the radio process' lease for
:data:`~backend.robot.radio_process.LEASE`, and more until :data:`~backend.robot.radio_process.LEASE_FRAMES`
are queued — and the radio process writes them on its own clock, whatever this interpreter is doing.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable

from backend.robot.link_types import LinkError
from backend.robot.radio_process import HEARTBEAT_PERIOD, LEASE_FRAMES


def keep_cadence(port, stop: threading.Event, next_frame: Callable[[], object | None]) -> None:
    """Until ``stop`` or the port closes: each period, the frames ``next_frame()`` gives (None: none
    now), picked and handed over under the port's write lock (a RESET takes them back under it)."""
    due = time.monotonic()
    while not stop.wait(max(0.0, due - time.monotonic())):
        due += HEARTBEAT_PERIOD
        if due <= time.monotonic():  # more than a period late: start the cadence afresh
            due = time.monotonic() + HEARTBEAT_PERIOD
        with port.write_lock:
            try:
                if not port.keeps_time:
                    message = next_frame()
                    if message is not None:
                        port.write(message)
                    continue
                top_up(port, next_frame)
            except LinkError:
                if not port.is_open:
                    return
                # Blocked (counted): the next one may pass; if none does, the robot disarms itself.


def top_up(port, next_frame: Callable[[], object | None]) -> None:
    """Hand a radio process' port one frame, which renews its lease (and says how many are queued),
    then more until LEASE_FRAMES are queued, in at most LEASE_FRAMES requests (a jammed line drains
    the queue as fast as it fills). Raises LinkError as the port does."""
    for _ in range(LEASE_FRAMES):
        message = next_frame()
        if message is None:
            return
        port.queue(message)
        if port.queued >= LEASE_FRAMES:
            return
