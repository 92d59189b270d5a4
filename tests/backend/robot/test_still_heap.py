"""A live run's thread on a frozen heap (backend/robot/still_heap.py): what is alive when a run
starts is out of the collector's sight until the run ends, so a full collection during the run
scans only what the run made."""

import gc
import threading

import pytest

from backend.robot.still_heap import on_a_still_heap


def _scanned() -> int:
    """Objects a full collection would scan now (the permanent generation's are not)."""
    return sum(len(gc.get_objects(generation)) for generation in range(3))


def test_a_run_sees_only_what_it_made_and_the_heap_thaws_after():
    alive = [(i, [i]) for i in range(50_000)]  # a service's heap, alive before the run
    seen = {}

    def loop():
        made = [[i] for i in range(1_000)]
        seen.update(frozen=gc.get_freeze_count(), scanned=_scanned(), made=len(made))

    before = _scanned()
    on_a_still_heap(loop)
    assert seen["frozen"] >= 100_000 and seen["scanned"] < 10_000 < before, (seen, before)
    assert gc.get_freeze_count() == 0 and _scanned() >= 100_000, "thawed once the run has ended"
    del alive


def test_a_loop_that_raises_thaws_the_heap_too():
    def loop():
        raise RuntimeError("the run's loop failed")

    with pytest.raises(RuntimeError):
        on_a_still_heap(loop)
    assert gc.get_freeze_count() == 0


def test_two_runs_at_once_thaw_when_the_last_ends():
    first_started, second_ended, release = threading.Event(), threading.Event(), threading.Event()

    def first():
        first_started.set()
        release.wait(10)

    thread = threading.Thread(target=on_a_still_heap, args=(first,))
    thread.start()
    first_started.wait(10)
    on_a_still_heap(second_ended.set)
    assert second_ended.is_set() and gc.get_freeze_count() > 0, "the first run's heap stays frozen"
    release.set()
    thread.join(10)
    assert gc.get_freeze_count() == 0
