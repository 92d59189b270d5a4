"""Big studies as lists of independent chunks, and the one hook that executes them.

A study (a basin, the trials of MJTF, the basins of a sweep, the orbits of a gait atlas) is split into chunk calls
``function(*arguments)`` of module-level sim_core functions with picklable arguments, and a
*chunk map* runs them, returning the results in order:

- :func:`in_process` (the default) runs them one after the other; each chunk already uses
  every core through the compiled kernels.
- ``experiments.cluster`` provides one that runs them on a Dask distributed cluster.

Results never depend on the chunk map or the chunk size: chunks are independent and any
randomness is seeded per trial. Progress is reported per finished chunk; a progress
callback may raise :class:`Cancelled` to stop between chunks (Ctrl-C does the same).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Protocol

Progress = Callable[[int, int], None]


class Cancelled(Exception):
    """Raised by a progress callback to stop a study between chunks."""


class ChunkMap(Protocol):
    def __call__(self, function: Callable, arguments: Sequence[tuple], progress: Progress | None = None) -> list: ...


def in_process(function: Callable, arguments: Sequence[tuple], progress: Progress | None = None) -> list:
    """Run the chunks here, in order; ``progress(done, total)`` after each."""
    results = []
    for done, chunk in enumerate(arguments, start=1):
        results.append(function(*chunk))
        if progress is not None:
            progress(done, len(arguments))
    return results


def chunk_slices(count: int, size: int) -> list[slice]:
    """``count`` items in consecutive slices of at most ``size``."""
    if size < 1:
        raise ValueError(f"chunk size must be >= 1, got {size}")
    return [slice(start, min(start + size, count)) for start in range(0, count, size)]
