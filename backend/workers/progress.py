"""How a call in a worker says how far it has got: :func:`report`, read in the service with
:meth:`backend.workers.pools.ComputePool.progress`.

Each pool's workers share one queue, handed to them as they start (:func:`attach`); a job's study
passes :func:`report` as its progress callback (``backend.services.studies.run_study_here``).
"""

from __future__ import annotations

_queue = None  # in a worker: the queue report() puts progress on (set as the worker starts)


def attach(queue) -> None:
    """In a worker, as it starts: where :func:`report` puts progress from now on."""
    global _queue
    _queue = queue


def report(done: int, total: int) -> None:
    """In a worker: tell the service how far the call has got (a job's chunks done of total).
    Anywhere else, nothing."""
    if _queue is not None:
        _queue.put((done, total))
