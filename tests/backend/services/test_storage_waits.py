"""Writes that wait for disk space (backend/services/storage_waits.py): retried until they fit, listed while
they wait, given up when the service stops."""

from __future__ import annotations

import threading

import pytest

from backend.services import storage_waits
from backend.services.storage_waits import Stopped, Waiting, now_or_when_room, when_room
from backend.store.database import StorageFull


class Disk:
    """A write that fails as a full disk does until ``free()``; counts its tries."""

    def __init__(self, full_tries: int | None) -> None:
        self.full_tries, self.tries = full_tries, 0
        self.freed = threading.Event()

    def write(self) -> str:
        self.tries += 1
        if not self.freed.is_set() and (self.full_tries is None or self.tries <= self.full_tries):
            raise StorageFull("INSERT", {}, Exception("database or disk is full"))
        return "stored"


@pytest.fixture(autouse=True)
def quick_retries(monkeypatch):
    monkeypatch.setattr(storage_waits, "STORAGE_RETRY", 0.01)
    monkeypatch.setattr(storage_waits, "after_storage_full", lambda _engine: None)  # no engine here: nothing to fold


def test_a_write_is_tried_again_until_it_fits_and_its_answer_returned(caplog):
    disk, waiting = Disk(full_tries=3), Waiting()
    assert when_room(disk.write, what="storing job 4's trials", engine=None, stopping=threading.Event(),
                     waiting=waiting) == "stored"  # fmt: skip
    assert disk.tries == 4 and waiting.notices() == ()
    assert "storing job 4's trials: paused" in caplog.text and "goes on" in caplog.text


def test_a_write_that_fits_at_once_logs_nothing(caplog):
    assert when_room(Disk(full_tries=0).write, what="x", engine=None, stopping=threading.Event()) == "stored"
    assert caplog.text == ""


def test_a_waiting_write_is_a_notice_until_it_fits():
    disk, waiting, stopping = Disk(full_tries=None), Waiting(), threading.Event()
    thread = now_or_when_room(disk.write, what="storing the live runs", engine=None, stopping=stopping, waiting=waiting)
    assert thread is not None
    (notice,) = waiting.notices()
    assert notice.startswith("the disk holding the database is full: storing the live runs waits for space")
    disk.freed.set()
    thread.join(5)
    assert not thread.is_alive() and waiting.notices() == ()


def test_a_write_that_fits_now_needs_no_thread():
    waiting = Waiting()
    assert now_or_when_room(Disk(0).write, what="x", engine=None, stopping=threading.Event(), waiting=waiting) is None
    assert waiting.notices() == ()


def test_stopping_the_service_gives_up_the_wait():
    stopping, outcome = threading.Event(), []

    def wait() -> None:
        try:
            when_room(Disk(full_tries=None).write, what="storing job 1's result", engine=None, stopping=stopping)
        except Stopped as stopped:
            outcome.append(stopped)

    waiter = threading.Thread(target=wait)
    waiter.start()
    stopping.set()
    waiter.join(5)
    assert not waiter.is_alive() and len(outcome) == 1, "the wait ends when the service stops, not when space returns"


def test_two_waits_for_one_thing_are_one_notice_until_both_end():
    waiting = Waiting()
    waiting.add("storing job 2's trials")
    waiting.add("storing job 2's trials")
    waiting.discard("storing job 2's trials")
    assert len(waiting.notices()) == 1
    waiting.discard("storing job 2's trials")
    assert waiting.notices() == ()
