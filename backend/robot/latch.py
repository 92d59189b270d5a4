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
waiting for a disk (an fsync can take a hundred milliseconds on a busy one), and only then waits
for the file (:meth:`EstopLatch.flush`) before it answers, so an answer that says latched is on disk:
a kill -9 right after it finds the latch held (before, 4 of 7 such kills forgot it).
:attr:`LatchState.durable` says whether the state is in the file yet.
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
    link sends it in place of heartbeats); ``since``: the press [``time.time()``], or None;
    ``pressed_by``: who pressed it (held), ``reset_by`` and ``reset_at``: who last reset it, when."""

    held: bool = False
    acknowledged: bool = False
    since: float | None = None
    pressed_by: str | None = None
    reset_by: str | None = None
    reset_at: float | None = None
    durable: bool = True  # in the file (or no file is kept); False from a change until it is written

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
        self._changes = 0  # changes handed to the writer (under the lock)
        self.save_error: str | None = None  # why the last write failed (None: it did not)
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
            self._state = LatchState(held=True, acknowledged=False, since=time.time(), durable=self.path is None)
            self._save()

    def attribute(self, pressed_by: str) -> None:
        """Who pressed the e-stop that holds the latch (the service knows after the robot's ESTOP went out)."""
        with self._lock:
            if self._state.held:
                self._state = replace(self._state, pressed_by=pressed_by, durable=self.path is None)
                self._save()

    def reset_by(self, person: str) -> None:
        """Who reset the latch just released (kept with the time, for whoever looks later)."""
        with self._lock:
            if not self._state.held:
                self._state = replace(self._state, reset_by=person, reset_at=time.time(), durable=self.path is None)
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
        """The robot acknowledged a RESET (who asked for it: :meth:`reset_by`)."""
        with self._lock:
            self._state = LatchState(
                durable=self.path is None, reset_by=self._state.reset_by, reset_at=self._state.reset_at
            )
            self._save()

    def flush(self, timeout: float | None = None) -> bool:
        """Wait until every change so far is in the file, up to ``timeout`` [s] (None: for as long as
        it takes); whether it is (False: not yet, or the write failed: :attr:`save_error`)."""
        try:
            self._writer.submit(lambda: None).result(timeout)
        except concurrent.futures.TimeoutError:
            return False
        return self._state.durable

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
        who = {
            name: saved.get(name) if isinstance(saved.get(name), str) else None for name in ("pressed_by", "reset_by")
        }
        reset_at = saved.get("reset_at") if isinstance(saved.get("reset_at"), int | float) else None
        if held:
            return LatchState(held=True, since=since, pressed_by=who["pressed_by"])
        return LatchState(reset_by=who["reset_by"], reset_at=reset_at)

    def _save(self) -> None:
        """Hand the state as it is now (under the lock) to the writer thread."""
        if self.path is not None:
            self._changes += 1
            self._writer.submit(self._write, self._state, self._changes)

    def _write(self, state: LatchState, change: int) -> None:
        """Write the latch whole (a temporary file, fsync, rename, the folder synced): a crash leaves
        the old or the new. The latest change written makes the state durable."""
        temporary = self.path.with_name(self.path.name + ".tmp")
        try:
            with open(temporary, "w") as file:
                json.dump({"held": state.held, "since": state.since, "pressed_by": state.pressed_by,
                           "reset_by": state.reset_by, "reset_at": state.reset_at}, file)  # fmt: skip
                file.flush()
                os.fsync(file.fileno())
            os.replace(temporary, self.path)
            _sync_folder(self.path.parent)  # the rename itself survives a power cut
        except OSError as error:  # a full disk must not stop the e-stop: it holds in memory all the same
            self.save_error = f"could not save the e-stop latch to {self.path}: {error}"
            log.error("%s", self.save_error)
            return
        self.save_error = None
        with self._lock:
            if change == self._changes:
                self._state = replace(self._state, durable=True)


def _sync_folder(folder: Path) -> None:
    descriptor = os.open(folder, os.O_RDONLY)
    try:
        os.fsync(descriptor)
    finally:
        os.close(descriptor)
