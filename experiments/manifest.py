"""Provenance and serialisation of what the lab writes: the code version, a study's manifest,
and the one sanitiser that turns results into strict JSON.

The figure studies (:mod:`experiments.reproduce`), the service (stored runs, jobs) and the CLI's
``--json`` all use these, so every output names the same code version and no output carries
NaN or infinities (not JSON).
"""

from __future__ import annotations

import datetime
import math
import subprocess
from dataclasses import asdict, is_dataclass
from pathlib import Path

import numpy as np


def code_version() -> str:
    """``git describe`` of the checkout (``-dirty`` with local changes), else the package version."""
    root = Path(__file__).resolve().parent.parent
    try:
        described = subprocess.run(
            ["git", "describe", "--always", "--dirty", "--tags"],
            cwd=root,
            capture_output=True,
            text=True,
            timeout=10,
            check=True,
        )
        return described.stdout.strip()
    except (OSError, subprocess.SubprocessError):
        from importlib.metadata import version

        return f"parkourlab {version('parkourlab')}"


def json_safe(value):
    """``value`` as plain JSON types: dataclasses, arrays and numpy scalars converted, NaN and
    infinities (not JSON) as None, recursively. The one sanitiser for every JSON we write."""
    if is_dataclass(value) and not isinstance(value, type):
        return json_safe(asdict(value))
    if isinstance(value, dict):
        return {str(key): json_safe(item) for key, item in value.items()}
    if isinstance(value, list | tuple):
        return [json_safe(item) for item in value]
    if isinstance(value, np.ndarray):
        return json_safe(value.tolist())
    if isinstance(value, np.generic):
        return json_safe(value.item())
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


def metadata(model, config) -> dict:
    """A study's manifest: its configuration, the model, the code version and when it ran (UTC)."""
    return {
        "config": config,
        "model": model,
        "code_version": code_version(),
        "created": datetime.datetime.now(datetime.UTC).isoformat(timespec="seconds"),
    }
