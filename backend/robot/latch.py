"""The e-stop latch: once pressed, it holds until the robot acknowledges a RESET (docs/protocol.md §3).

One :class:`EstopLatch` belongs to the service, not to a link: a link lost and reconnected by the
supervisor, a new connect by hand, and a service restart (the latch is kept in a file) all find it
still held. While it holds, every link it is given sends the ESTOP until the robot acknowledges it
— on every new connection again, since a robot that was out of range or restarted may not be
e-stopped — and refuses ARM and START. Only a RESET that the robot acknowledges releases it.

Thread-safe: the e-stop's thread engages it, a link's reader marks it acknowledged, a request's
thread releases it; readers take :attr:`EstopLatch.state`, an immutable :class:`LatchState`.

The file (JSON, written whole and atomically) says only whether it holds and since when; one that
cannot be read is taken as held — a latch that cannot be proven released holds. It is written by
the latch's own writer thread, in the order of the changes: the e-stop sends its ESTOP without
waiting for a disk (an fsync can take a hundred milliseconds on a busy one).
"""

from __future__ import annotations

import concurrent.futures
import json
import logging
import os
import threading
import time
from dataclasses import dataclass, replace
from pathlib import Path

log = logging.getLogger("parkourlab.robot")


@dataclass(frozen=True)
class LatchState:
    """The latch as it is now. ``held``: an e-stop was pressed and no RESET acknowledged since;
    ``acknowledged``: the robot has confirmed the ESTOP on the current connection (until then the
    link sends it in place of heartbeats); ``since``: the press [``time.time()``], or None."""

    held: bool = False
    acknowledged: bool = False
    since: float | None = None

    @property
    def pending(self) -> bool:
        """Held, and the robot has not confirmed the ESTOP on this connection: it must be sent."""
        return self.held and not self.acknowledged

    def reason(self) -> str | None:
        """Why it holds, in the operator's words (None when released)."""
        if not self.held:
            return None
        if self.acknowledged:
            return "emergency stop: the robot acknowledged it; it holds until a reset"
        return (
            "emergency stop not yet acknowledged by the robot: the PC sends it in place of heartbeats "
            "(the robot's watchdog disarms it within 1 s); it holds until a reset"
        )


class EstopLatch:
    """The service's one e-stop latch, kept in ``path`` (None: in memory only, for tests and tools)."""

    def __init__(self, path: Path | None = None):
        self.path = path
        self._lock = threading.Lock()
        self._state = self._load()
        self._writer = concurrent.futures.ThreadPoolExecutor(1, thread_name_prefix="estop-latch-writer")

    @property
    def state(self) -> LatchState:
        return self._state

    @property
    def held(self) -> bool:
        return self._state.held

    def engage(self) -> None:
        """An e-stop was pressed: held, not yet acknowledged (a press while held starts it afresh)."""
        with self._lock:
            self._state = LatchState(held=True, acknowledged=False, since=time.time())
            self._save()

    def acknowledged(self) -> None:
        """The robot confirmed the ESTOP on the current connection."""
        with self._lock:
            if self._state.held:
                self._state = replace(self._state, acknowledged=True)

    def unconfirmed(self) -> None:
        """A new connection: a held latch must be confirmed by the robot again."""
        with self._lock:
            if self._state.held:
                self._state = replace(self._state, acknowledged=False)

    def release(self) -> None:
        """The robot acknowledged a RESET."""
        with self._lock:
            self._state = LatchState()
            self._save()

    def flush(self) -> None:
        """Wait until every change so far is in the file."""
        self._writer.submit(lambda: None).result()

    def _load(self) -> LatchState:
        if self.path is None or not self.path.exists():
            return LatchState()
        try:
            saved = json.loads(self.path.read_text())
            held, since = saved["held"], saved.get("since")
            if not isinstance(held, bool) or not (since is None or isinstance(since, int | float)):
                raise ValueError("held must be true or false, since a time or null")
        except (OSError, ValueError, KeyError, TypeError) as error:
            log.warning("e-stop latch file %s unreadable (%s): the latch holds until a reset", self.path, error)
            return LatchState(held=True, since=None)
        return LatchState(held=held, since=since if held else None)

    def _save(self) -> None:
        """Hand the state as it is now (under the lock) to the writer thread."""
        if self.path is not None:
            self._writer.submit(self._write, self._state)

    def _write(self, state: LatchState) -> None:
        """Write the latch whole (a temporary file, fsync, rename): a crash leaves the old or the new."""
        temporary = self.path.with_name(self.path.name + ".tmp")
        try:
            with open(temporary, "w") as file:
                json.dump({"held": state.held, "since": state.since}, file)
                file.flush()
                os.fsync(file.fileno())
            os.replace(temporary, self.path)
        except OSError as error:  # a full disk must not stop the e-stop: it holds in memory all the same
            log.error("could not save the e-stop latch to %s: %s", self.path, error)
