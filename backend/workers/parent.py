"""The parent watch: a worker process ends once the service that started it is gone.

A service killed outright (kill -9, out of memory) stops no workers, and a worker waits on its
task queue forever (it holds the queue's writing end itself): each crash left its workers — a read
worker's store connection among them — until the machine restarted. So every worker runs
:func:`exit_with_parent` on a daemon thread from its start (:func:`watch_parent`).
"""

from __future__ import annotations

import os
import threading
import time

PARENT_CHECK_S = 1.0  # [s] how often a worker checks that the service that started it is alive


def watch_parent() -> None:
    """In a worker, as it starts: end this process once its parent is gone (in the background)."""
    threading.Thread(target=exit_with_parent, args=(os.getppid(),), name="exit-with-parent", daemon=True).start()


def exit_with_parent(parent: int) -> None:
    """End this process once process ``parent`` is no longer its parent (it died; the worker was re-parented)."""
    while os.getppid() == parent:
        time.sleep(PARENT_CHECK_S)
    os._exit(0)
