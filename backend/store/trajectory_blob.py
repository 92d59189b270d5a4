"""A run's sampled path as the store keeps it: the columns as one compressed ``.npz`` blob.

A run stays one row however many samples it has (``runs.trajectory``); simulated runs, live
robot runs and recordings are packed and read back here, and nowhere else.
"""

from __future__ import annotations

import io
import zlib

import numpy as np


def pack_trajectory(columns: dict[str, np.ndarray]) -> bytes:
    """Columns as one compressed .npz blob: a run stays one row however many samples it has."""
    buffer = io.BytesIO()
    np.savez(buffer, **columns)
    return zlib.compress(buffer.getvalue(), level=6)


def unpack_trajectory(blob: bytes) -> dict[str, np.ndarray]:
    """The columns of a blob :func:`pack_trajectory` wrote, as arrays of their own (not views of the file)."""
    with np.load(io.BytesIO(zlib.decompress(blob))) as data:
        return {name: data[name] for name in data.files}
