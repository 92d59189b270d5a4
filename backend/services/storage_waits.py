"""Writes that wait for disk space: what the service must store but can hold on to meanwhile.

On a full disk a write fails at once (:class:`~backend.store.database.StorageFull`, the API's 507),
and the caller that can wait — a job's computed trials, the recovery of jobs and live runs a crash
left unfinished — tries again every :data:`STORAGE_RETRY` until the write fits, instead of failing
(or failing start-up: reads and DELETE, the way to free space, must stay reachable). Each waiting
write is listed in :class:`Waiting`, which ``GET /api/v1/health`` shows as notices.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable
from typing import TypeVar

from backend.store.database import StorageFull, after_storage_full

log = logging.getLogger("parkourlab.store")
T = TypeVar("T")
STORAGE_RETRY = 5.0  # [s] between tries of a write that waits for space


class Stopped(Exception):
    """The service is stopping while a write waits for disk space (it was not made)."""


class Waiting:
    """The writes waiting for disk space now, by what they store (thread-safe; read as a snapshot)."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._waiting: dict[str, int] = {}

    def add(self, what: str) -> None:
        with self._lock:
            self._waiting[what] = self._waiting.get(what, 0) + 1

    def discard(self, what: str) -> None:
        with self._lock:
            left = self._waiting.pop(what, 1) - 1
            if left:
                self._waiting[what] = left

    def notices(self) -> tuple[str, ...]:
        """One line per waiting write, in the user's terms."""
        with self._lock:
            waiting = tuple(self._waiting)
        return tuple(f"the disk holding the database is full: {what} waits for space (delete runs to free some)"
                     for what in waiting)  # fmt: skip


def when_room(
    write: Callable[[], T],
    *,
    what: str,
    engine,
    stopping: threading.Event,
    waiting: Waiting | None = None,
    retry_s: float | None = None,
) -> T:
    """``write()`` (one transaction, rolled back by itself when it fails), again every ``retry_s``
    while the disk is full; its answer once it fits.

    Args:
        what: the write in words, for the log and the notices ("storing job 4's trials").
        engine: the store's engine (its WAL is folded after each failure, so a retry can fit).
        stopping: set when the service stops; a write still waiting then raises :class:`Stopped`.
        retry_s: seconds between tries; default :data:`STORAGE_RETRY`.

    Raises:
        Stopped: the service stopped before there was room.
    """
    retry_s = STORAGE_RETRY if retry_s is None else retry_s
    paused = False
    try:
        while True:
            try:
                answer = write()
            except StorageFull:
                after_storage_full(engine)
                if not paused:
                    log.warning("%s: paused, the disk holding the database is full; goes on when there is room", what)
                    paused = True
                    if waiting is not None:
                        waiting.add(what)
                if stopping.wait(retry_s):
                    raise Stopped(what) from None
                continue
            if paused:
                log.warning("%s: goes on, it fits again", what)
            return answer
    finally:
        if paused and waiting is not None:
            waiting.discard(what)


def now_or_when_room(write: Callable[[], object], *, what: str, engine, stopping: threading.Event,
                     waiting: Waiting | None = None) -> threading.Thread | None:  # fmt: skip
    """``write()`` now; on a full disk, again on a thread of its own until it fits (:func:`when_room`),
    so the caller — the service's start — goes on. That thread, or None if the write was made now."""
    try:
        write()
        return None
    except StorageFull:
        after_storage_full(engine)

    def retry() -> None:
        try:
            when_room(write, what=what, engine=engine, stopping=stopping, waiting=waiting)
        except Stopped:
            log.warning("%s still waits for space; the next start tries again", what)
        finally:
            if waiting is not None:
                waiting.discard(what)

    if waiting is not None:
        waiting.add(what)  # listed from now, not from the thread's first failure
    thread = threading.Thread(target=retry, name="parkourlab-room", daemon=True)
    thread.start()
    return thread
