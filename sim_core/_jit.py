"""How sim_core compiles its kernels: the ``kernel`` decorators and where numba caches them.

``error_model="numpy"``: division by zero gives inf/NaN instead of raising, which drops the
zero-division checks of the default Python error model (about 30% of the stance kernel's
time). The kernels never raise anyway: they report non-finite results as ``invalid_state``.
No ``fastmath``: it would break agreement with the reference.

The cache lives in a directory keyed by a hash of sim_core's source, every package's modules.

numba invalidates a cached function when *its own* file changes, not when a kernel it
inlines from another file does (``stride.orbit`` inlines ``integrate.stance``), so a plain
``cache=True`` can silently run stale machine code after an edit or an upgrade. Keying the
cache directory on all of sim_core's source makes any change start from a clean cache.
Every kernel module imports its decorator from here, so the cache is configured first.
"""

from __future__ import annotations

import functools
import hashlib
import os
from pathlib import Path

import numba


def _source_hash() -> str:
    digest = hashlib.sha256()
    root = Path(__file__).parent
    for path in sorted(root.rglob("*.py")):  # every package's modules: a kernel in any may change
        digest.update(path.relative_to(root).as_posix().encode())
        digest.update(path.read_bytes())
    digest.update(numba.__version__.encode())
    return digest.hexdigest()[:16]


def configure() -> Path:
    """Point numba's cache at ``$PARKOUR_CACHE_DIR`` (default ``~/.cache/parkourlab``)/numba/<hash>."""
    root = os.environ.get("PARKOUR_CACHE_DIR") or os.path.join(
        os.environ.get("XDG_CACHE_HOME") or os.path.expanduser("~/.cache"), "parkourlab"
    )
    directory = Path(root) / "numba" / _source_hash()
    numba.config.CACHE_DIR = str(directory)
    return directory


CACHE_DIR = configure()

kernel = functools.partial(numba.njit, cache=True, error_model="numpy")
parallel_kernel = functools.partial(numba.njit, cache=True, parallel=True, error_model="numpy")
