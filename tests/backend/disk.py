"""A real full filesystem for the full-disk tests: a small tmpfs, mounted where a test asks.

Mounting needs root (or CAP_SYS_ADMIN); elsewhere the tests that use it skip. ``fill`` takes the
free space the way a log or a big download would, so the filesystem is full in the ordinary sense
(``write`` fails with ENOSPC), not by a simulation.
"""

from __future__ import annotations

import contextlib
import errno
import os
import shutil
import subprocess
from collections.abc import Iterator
from pathlib import Path

import pytest


@contextlib.contextmanager
def tmpfs(path: Path, size: str) -> Iterator[Path]:
    """A tmpfs of ``size`` (e.g. ``"8m"``) mounted at ``path`` for the duration; skips if it cannot be."""
    path.mkdir(parents=True, exist_ok=True)
    if os.geteuid() != 0 or shutil.which("mount") is None:
        pytest.skip("mounting a small tmpfs needs root")
    mounted = subprocess.run(["mount", "-t", "tmpfs", "-o", f"size={size},mode=0700", "tmpfs", str(path)], check=False)
    if mounted.returncode != 0:
        pytest.skip("could not mount a small tmpfs here")
    try:
        yield path
    finally:
        subprocess.run(["umount", "-l", str(path)], check=False)


def fill(directory: Path, name: str = "ballast") -> Path:
    """Write zeros into ``directory/name`` until the filesystem is full; the file that took the space."""
    ballast = directory / name
    chunk = b"\0" * 65536
    with ballast.open("ab", buffering=0) as out:
        for size in (65536, 4096, 512, 1):
            try:
                while True:
                    out.write(chunk[:size])
            except OSError as error:
                assert error.errno == errno.ENOSPC, error
    return ballast


def free_bytes(directory: Path) -> int:
    stats = os.statvfs(directory)
    return stats.f_bavail * stats.f_frsize
