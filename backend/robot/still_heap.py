"""A live run's interpreter kept free of long garbage collections.

A full (oldest-generation) collection scans every object the interpreter tracks and holds every
thread while it does: the tracker's receiving thread and the run's loop alike. Measured in the
realtime tests' process (the service and the virtual robot in one interpreter) it grew with the
heap to 215-227 ms at 220,000-280,000 objects; one such pause longer than the tracker's bound (100
ms; twice that with datagrams waiting) ends a closed loop "tracker silent" though the camera never
stopped (a CI run: "tracker silent 461 ms" after one touchdown). So a run's thread freezes the heap
as the run starts (:func:`gc.freeze`: every object alive then moves out of the collector's sight,
at no cost) and thaws it when the run has ended and been stored: the run's collections scan only
what the run itself made. Nothing alive at the start is freed during the run — garbage cycles of
before included, which the first collection after the thaw frees.
"""

from __future__ import annotations

import gc
import threading
from collections.abc import Callable

_lock = threading.Lock()
_frozen_by = 0  # runs under way with the heap frozen (one robot: one at most, but tests make several)


def on_a_still_heap(loop: Callable[[], None]) -> None:
    """``loop()`` (a live run's, on its own thread) with the heap frozen until it returns."""
    global _frozen_by
    with _lock:
        _frozen_by += 1
        gc.freeze()
    try:
        loop()
    finally:
        with _lock:
            _frozen_by -= 1
            if _frozen_by == 0:
                gc.unfreeze()
