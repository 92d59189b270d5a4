"""Running studies on a Dask distributed cluster: a chunk map for :mod:`sim_core.chunks`.

Given a scheduler address (``--scheduler tcp://host:8786`` or ``$PARKOUR_DASK_SCHEDULER``),
a study's chunks are submitted to that cluster and gathered in order; without one they run
in-process. Results are identical either way (chunks are independent and seeded).

Workers need ParkourLab installed (the same ``.venv``) so they can import ``sim_core``. Start
them with one thread each (``dask worker ADDRESS --nthreads 1``): each chunk already uses
every core of its machine through numba, and numba's default threading layer does not allow
two parallel kernels at once in one process.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager

from sim_core.chunks import ChunkMap, Progress, in_process
from sim_core.model.validation import ParameterError

SCHEDULER_ENV = "PARKOUR_DASK_SCHEDULER"
CONNECT_TIMEOUT = "10s"


def scheduler_address(option: str | None = None) -> str | None:
    """The scheduler to use: the option if given, else ``$PARKOUR_DASK_SCHEDULER``, else None."""
    address = option if option is not None else os.environ.get(SCHEDULER_ENV)
    return address or None


@contextmanager
def chunk_map_for(address: str | None, *, timeout: str = CONNECT_TIMEOUT) -> Iterator[ChunkMap]:
    """A chunk map for ``address`` (None: in-process), connected for the ``with`` block."""
    if address is None:
        yield in_process
        return
    with dask_client(address, timeout=timeout) as client:
        yield _DaskChunkMap(client)


def as_completed_results(client, function: Callable, arguments: Sequence[tuple]) -> Iterator[tuple[int, object]]:
    """Submit one task per chunk; yield ``(chunk index, result)`` as each finishes.

    Closing the generator early (a cancelled job, an error, Ctrl-C) cancels the chunks not yet
    finished, so the cluster is freed at once.
    """
    from distributed import as_completed

    futures = [client.submit(function, *chunk, pure=False) for chunk in arguments]
    index_of = {future.key: index for index, future in enumerate(futures)}
    try:
        for future in as_completed(futures, loop=client.loop):
            yield index_of[future.key], future.result()
    finally:
        client.cancel([future for future in futures if not future.done()])


@contextmanager
def dask_client(address: str, *, timeout: str = CONNECT_TIMEOUT):
    """A connected client for the ``with`` block; an unreachable scheduler is a ParameterError."""
    from distributed import Client  # imported only when a cluster is asked for: it is heavy

    try:
        client = Client(address, timeout=timeout, set_as_default=False)
    except (OSError, TimeoutError) as error:
        raise ParameterError("scheduler", f"cannot reach the Dask scheduler at {address!r}: {error}") from None
    try:
        yield client
    finally:
        client.close()


class _DaskChunkMap:
    def __init__(self, client):
        self.client = client

    def __call__(self, function: Callable, arguments: Sequence[tuple], progress: Progress | None = None) -> list:
        results: list = [None] * len(arguments)
        for done, (index, result) in enumerate(as_completed_results(self.client, function, arguments), start=1):
            results[index] = result
            if progress is not None:
                progress(done, len(arguments))
        return results
