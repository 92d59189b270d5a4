"""A disk cache of built MFPT chains (:class:`sim_core.robustness.mfpt_chain.Chain`), so a repeated
:func:`sim_core.robustness.mfpt.mfpt` loads its two chains instead of rebuilding them (20-50 s with the pitch
drifting).

An entry is ``<root>/mfpt/<key>.npz``, ``<root>`` numba's cache root (:mod:`sim_core._jit`:
``$PARKOUR_CACHE_DIR``, default ``~/.cache/parkourlab``). The key is a SHA-256 of everything the
chain is built from: the model's kernel arguments, the controls, the noise's kernel arguments,
the grid's fields, the start, :data:`FORMAT` and the hash of sim_core's source that numba's cache
directory is named by (so any code change, or a numba upgrade, misses). Entries are written to a
temporary file beside them and moved into place, so a reader never sees half an entry; one that
cannot be read is deleted and rebuilt. The cache keeps at most :data:`MAX_ENTRIES` entries and
:data:`MAX_BYTES` bytes, evicting the least recently used (a hit refreshes an entry's mtime);
entries of older source are never hit again and go that way. ``PARKOUR_MFPT_CACHE=0`` turns it off.

Imports no numba at module level: :mod:`sim_core._jit` is imported when a key is made.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
import tempfile
from dataclasses import asdict
from pathlib import Path

import numpy as np

FORMAT = 1  # bump when what an entry holds changes
MAX_ENTRIES = 64
MAX_BYTES = 2 * 1024**3
DISABLED = ("0", "false", "no", "off")
_ARRAYS = ("xdots", "ydots", "pitches", "state_of", "success")
_MATRICES = ("steps", "jumps")


def cache_root() -> Path:
    """``<root>/mfpt`` beside numba's ``<root>/numba/<source hash>``."""
    from sim_core._jit import CACHE_DIR

    return CACHE_DIR.parent.parent / "mfpt"


def enabled() -> bool:
    """False when ``$PARKOUR_MFPT_CACHE`` says off (0, false, no, off)."""
    return os.environ.get("PARKOUR_MFPT_CACHE", "1").strip().lower() not in DISABLED


def chain_key(model, controls, noise, start, grid) -> str:
    """SHA-256 (hex) of every input :func:`sim_core.robustness.mfpt_chain.build_chain` depends on."""
    from sim_core._jit import CACHE_DIR

    inputs = {
        "format": FORMAT,
        "source": CACHE_DIR.name,  # sim_core's source and numba's version, as numba's cache
        "numpy": np.__version__,
        "model": [float(value) for value in model.record()],
        "controls": [float(controls.psi0), float(controls.zeta0)],
        "noise": [float(value) for value in noise.record()],
        "start": [float(value) for value in np.asarray(start, dtype=float).ravel()],
        "grid": asdict(grid),
    }
    return hashlib.sha256(json.dumps(inputs, sort_keys=True).encode()).hexdigest()


class ChainCache:
    """Built chains on disk under ``directory`` (default :func:`cache_root`), bounded by
    ``max_entries`` and ``max_bytes``."""

    def __init__(self, directory=None, max_entries: int = MAX_ENTRIES, max_bytes: int = MAX_BYTES):
        self.directory = Path(directory) if directory is not None else cache_root()
        self.max_entries = max_entries
        self.max_bytes = max_bytes

    def path(self, key: str) -> Path:
        return self.directory / f"{key}.npz"

    def load(self, key: str):
        """The chain stored under ``key``, or None (absent, or unreadable: then deleted)."""
        path = self.path(key)
        if not path.is_file():
            return None
        try:
            chain = _read(path, key)
        except Exception:  # any damage to an entry (a truncated zip, a missing array): rebuild it
            with contextlib.suppress(OSError):
                path.unlink()
            return None
        with contextlib.suppress(OSError):
            os.utime(path)  # least recently used goes first
        return chain

    def store(self, key: str, chain) -> bool:
        """Write ``chain`` under ``key`` atomically, then evict past the bounds; False when the
        disk refuses (the cache is an optimisation: never an error)."""
        try:
            self.directory.mkdir(parents=True, exist_ok=True)
            handle, temporary = tempfile.mkstemp(prefix=f".{key[:16]}.", suffix=".tmp", dir=self.directory)
            try:
                with os.fdopen(handle, "wb") as file:
                    np.savez(file, **_arrays_of(chain, key))
                os.replace(temporary, self.path(key))
            except BaseException:
                with contextlib.suppress(OSError):
                    os.unlink(temporary)
                raise
        except OSError:
            return False
        self.evict()
        return True

    def evict(self) -> None:
        """Delete the least recently used entries until at most ``max_entries`` and ``max_bytes`` remain."""
        entries = []
        for path in self.directory.glob("*.npz"):
            with contextlib.suppress(OSError):
                stat = path.stat()
                entries.append((stat.st_mtime, stat.st_size, path))
        entries.sort(key=lambda entry: entry[0], reverse=True)  # newest first
        kept, total = 0, 0
        for _, size, path in entries:
            if kept < self.max_entries and total + size <= self.max_bytes:
                kept, total = kept + 1, total + size
                continue
            with contextlib.suppress(OSError):
                path.unlink()


def _arrays_of(chain, key: str) -> dict:
    arrays = {name: np.asarray(getattr(chain, name)) for name in _ARRAYS}
    for name in _MATRICES:
        matrix = getattr(chain, name).tocsr()
        arrays[f"{name}_data"] = matrix.data
        arrays[f"{name}_indices"] = matrix.indices
        arrays[f"{name}_indptr"] = matrix.indptr
        arrays[f"{name}_shape"] = np.asarray(matrix.shape, dtype=np.int64)
    arrays["escaped"] = np.asarray(chain.escaped, dtype=float)
    arrays["key"] = np.asarray(key)
    return arrays


def _read(path: Path, key: str):
    from scipy import sparse

    from sim_core.robustness.mfpt_chain import Chain

    with np.load(path, allow_pickle=False) as stored:
        if str(stored["key"]) != key:
            raise ValueError(f"{path.name} holds another key")
        arrays = {name: stored[name] for name in _ARRAYS}
        matrices = {
            name: sparse.csr_matrix(
                (stored[f"{name}_data"], stored[f"{name}_indices"], stored[f"{name}_indptr"]),
                shape=tuple(int(n) for n in stored[f"{name}_shape"]),
            )
            for name in _MATRICES
        }
        escaped = float(stored["escaped"])
    states, layers = arrays["success"].size, arrays["pitches"].size
    nodes = arrays["xdots"].size * arrays["ydots"].size
    steps, jumps = matrices["steps"], matrices["jumps"]
    if (
        arrays["state_of"].shape != (layers, nodes)
        or steps.shape != (states, jumps.shape[0])
        or jumps.shape[1] != states
        or int(arrays["state_of"].max(initial=-1)) != states - 1
    ):
        raise ValueError(f"{path.name} is not a consistent chain")
    for matrix in matrices.values():
        matrix.check_format(full_check=True)
    return Chain(steps=steps, jumps=jumps, escaped=escaped, **arrays)
