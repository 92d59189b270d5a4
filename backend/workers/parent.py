"""The parent watch: a worker process ends once the service that started it is gone.

A service killed outright (kill -9, out of memory) stops no workers, and a worker waits on its
task queue forever (it holds the queue's writing end itself): each crash left its workers — a read
worker's store connection among them — until the machine restarted. So every worker runs
:func:`exit_with_parent` on a daemon thread from its start (:func:`watch_parent`).

The service's process id comes from the service (:func:`watch_parent`'s argument), not from the
worker's own ``os.getppid()`` as it starts: a worker spawned while the service is ending (the job
runner's next job, a pool restarted by a cancel) may start after the service is gone, already
re-parented, and one that took its new parent for the service's waited forever (issue 40: a
fresh job worker, and the resource tracker it kept, alive 14 min after a SIGTERM).

Not ``prctl(PR_SET_PDEATHSIG)``: the kernel sends it when the *thread* that started the worker
ends, and the pools start workers from request threads, which anyio ends when idle.
"""

from __future__ import annotations

import os
import threading
import time

PARENT_CHECK_S = 1.0  # [s] how often a worker checks that the service that started it is alive


def watch_parent(parent: int) -> None:
    """In a worker, as it starts: end this process once ``parent`` (the service's process id, as
    the service gave it) is no longer its parent — at once if it is not now."""
    threading.Thread(target=exit_with_parent, args=(parent,), name="exit-with-parent", daemon=True).start()


def exit_with_parent(parent: int) -> None:
    """End this process once process ``parent`` is no longer its parent (it died; the worker was re-parented)."""
    while os.getppid() == parent:
        time.sleep(PARENT_CHECK_S)
    os._exit(0)
