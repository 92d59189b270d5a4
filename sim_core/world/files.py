"""World files (docs/model.md §8, docs/worlds.md): a world as JSON, read, checked and written.

A world file is ``{"units": "l0" | "m", "left": {"points": [[x, y], ...], "mu": [...]}, "right":
{...}}`` with an optional ``"name"`` and ``"description"``. Points are wall coordinates bottom to
top; ``mu`` (optional: all the model's ``mu``) has one entry per segment, a number ``>= 0``,
``null`` (the model's ``mu``) or the string ``"inf"`` (no slip). Metres are converted to ``l0``
with the robot's leg length; inside, a :class:`~sim_core.world.world.World` is in ``l0``.

Every mistake is a :class:`~sim_core.model.errors.ParameterError` naming where it is
(``"left.points[3]"``, ``"right.mu[2]"``, ``"units"``) and the rule it breaks.
"""

from __future__ import annotations

import json
import math
import re
from pathlib import Path

import numpy as np

from sim_core.model.errors import ParameterError
from sim_core.model.validation import check_range
from sim_core.world.validation import check_point_count, check_side, check_sides_apart, check_world
from sim_core.world.world import SIDES, Side, World

UNITS = ("l0", "m")
WORLD_KEYS = ("name", "description", "units", *SIDES)
SIDE_KEYS = ("points", "mu")
NO_SLIP = "inf"


def world_from_document(document: dict, l0_m: float | None = None, *, default_name: str = "") -> World:
    """The world a parsed world file describes, in ``l0``.

    Args:
        document: the file's JSON object.
        l0_m: the leg length ``l0`` [m] that converts a world in metres (unused for ``"l0"``).
        default_name: the world's name when the document has none.
    """
    if not isinstance(document, dict):
        raise ParameterError(
            "world", f'must be a JSON object {{"units": ..., "left": ..., "right": ...}}, got {_shown(document)}'
        )
    _check_keys("", document, WORLD_KEYS)
    units = document.get("units")
    if "units" not in document:
        raise ParameterError("units", 'is required: "l0" (leg lengths) or "m" (metres)')
    if units not in UNITS:
        raise ParameterError("units", f'must be "l0" or "m", got {_shown(units)}')
    for key in ("name", "description"):
        if not isinstance(document.get(key, ""), str):
            raise ParameterError(key, f"must be a string, got {_shown(document[key])}")
    sides = {name: _side_arrays(name, document.get(name)) for name in SIDES}
    check_sides_apart(sides["left"][0], sides["right"][0])
    scale = 1.0
    if units == "m":
        if l0_m is None:
            raise ParameterError("l0_m", "a world in metres needs the leg length l0 [m] to convert it to l0")
        scale = check_range("l0_m", l0_m, 0.0)
    left, right = (Side(points / scale, mu) for points, mu in sides.values())
    return World(left, right, document.get("name", default_name))


def world_to_document(world: World, units: str = "l0", l0_m: float | None = None, *, description: str = "") -> dict:
    """The world file of ``world`` (checked first), in ``units`` (``"l0"``, or ``"m"`` with ``l0_m``
    [m]); :func:`world_from_document` reads it back to the same world."""
    check_world(world)
    if units not in UNITS:
        raise ParameterError("units", f'must be "l0" or "m", got {units!r}')
    scale = 1.0
    if units == "m":
        if l0_m is None:
            raise ParameterError("l0_m", "a world in metres needs the leg length l0 [m]")
        scale = check_range("l0_m", l0_m, 0.0)
    document: dict = {"name": world.name} if world.name else {}
    if description:
        document["description"] = description
    document["units"] = units
    for name in SIDES:
        side = world.side(name)
        document[name] = {"points": (side.points * scale).tolist(), "mu": [_mu_entry(value) for value in side.mu]}
    return document


def read_document(path: Path | str) -> dict:
    """A world file's JSON (not yet checked); :class:`ParameterError` naming the file if it is not
    JSON, ``OSError`` if it cannot be read."""
    path = Path(path)
    try:
        return json.loads(path.read_text())
    except json.JSONDecodeError as error:
        raise ParameterError(
            str(path), f"is not JSON: {error.msg} at line {error.lineno} column {error.colno}"
        ) from None


def load_world(path: Path | str, l0_m: float | None = None) -> World:
    """The world in the file at ``path`` (named after the file if it names itself not); ``l0_m``
    [m] converts a world in metres."""
    return world_from_document(read_document(path), l0_m, default_name=Path(path).stem)


def save_world(
    world: World, path: Path | str, units: str = "l0", l0_m: float | None = None, *, description: str = ""
) -> None:
    """Write ``world`` as a world file at ``path``, one point per line."""
    text = json.dumps(world_to_document(world, units, l0_m, description=description), indent=2)
    # json's indent puts every coordinate on a line of its own; a point reads better as [x, y].
    text = re.sub(r"\[\s+([^\[\]\s,]+),\s+([^\[\]\s,]+)\s+\]", r"[\1, \2]", text)
    Path(path).write_text(text + "\n")


def _side_arrays(name: str, side: object) -> tuple[np.ndarray, np.ndarray]:
    """One side of a document as ``(points, mu)`` arrays in the file's units, checked."""
    if side is None:
        raise ParameterError(name, 'is required: {"points": [[x, y], ...], "mu": [...]}')
    if not isinstance(side, dict):
        raise ParameterError(name, f'must be an object {{"points": [[x, y], ...], "mu": [...]}}, got {_shown(side)}')
    _check_keys(f"{name}.", side, SIDE_KEYS)
    listed = side.get("points")
    if not isinstance(listed, list):
        raise ParameterError(f"{name}.points", f"must be a list of [x, y] pairs bottom to top, got {_shown(listed)}")
    check_point_count(name, len(listed))
    points = np.array([_point(f"{name}.points[{index}]", point) for index, point in enumerate(listed)])
    entries = side.get("mu", [None] * (len(listed) - 1))
    if not isinstance(entries, list):
        raise ParameterError(f"{name}.mu", f"must be a list with one entry per segment, got {_shown(entries)}")
    mu = np.array([_mu_value(f"{name}.mu[{index}]", entry) for index, entry in enumerate(entries)], dtype=float)
    check_side(name, points, mu)
    return points, mu


def _point(field: str, point: object) -> tuple[float, float]:
    if not (isinstance(point, list) and len(point) == 2 and all(_is_number(value) for value in point)):
        raise ParameterError(field, f"must be a pair [x, y] of numbers, got {_shown(point)}")
    return _float(point[0]), _float(point[1])


def _mu_value(field: str, entry: object) -> float:
    """A ``mu`` entry as a number: null -> NaN (the model's mu), "inf" -> inf."""
    if entry is None:
        return math.nan
    if entry == NO_SLIP:
        return math.inf
    if not _is_number(entry) or not _float(entry) >= 0:  # NaN fails >= 0 too
        raise ParameterError(field, f'must be >= 0, null or "inf", got {_shown(entry)}')
    return _float(entry)


def _mu_entry(value: float) -> float | str | None:
    if math.isnan(value):
        return None
    return NO_SLIP if math.isinf(value) else float(value)


def _check_keys(prefix: str, mapping: dict, known: tuple[str, ...]) -> None:
    for key in mapping:
        if key not in known:
            where = "a world file" if not prefix else "a side"
            raise ParameterError(f"{prefix}{key}", f"is not a key of {where}; its keys are {', '.join(known)}")


def _is_number(value: object) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool)


def _float(value: int | float) -> float:
    """A JSON number as a float; an integer too big for one is infinite (and so refused as such)."""
    try:
        return float(value)
    except OverflowError:
        return math.inf if value > 0 else -math.inf


def _shown(value: object) -> str:
    """A value as the file wrote it (JSON), shortened."""
    try:
        text = json.dumps(value)
    except (TypeError, ValueError):
        text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."
