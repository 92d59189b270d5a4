"""Provenance: the code version that every stored run, job, calibration and export is stamped with.

``git describe`` of the checkout (``-dirty`` with local changes), else the package's version
(:func:`experiments.manifest.code_version`), read once per process and cut to its column's width.
"""

from __future__ import annotations

from experiments.manifest import code_version

CODE_VERSION_WIDTH = 64  # the stored column's width
_CODE_VERSION = None


def current_code_version() -> str:
    global _CODE_VERSION
    if _CODE_VERSION is None:
        _CODE_VERSION = code_version()[:CODE_VERSION_WIDTH]
    return _CODE_VERSION
