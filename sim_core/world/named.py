"""Named worlds (docs/worlds.md): chutes every tool knows by name, built for the model's ``d_hat``.

:data:`NAMED_WORLDS` is the one registry: a name, a builder ``d_hat -> World`` and a description
for people. A new named world is one builder and one entry; ``parkour world list`` and every
``NAME|FILE`` argument read it. All are 2 m tall, as the lab's table, in the paper's ``l0``
(:data:`CHUTE_HEIGHT`, about 8.96 ``l0``); past their ends the sides go on as vertical walls with
the model's ``mu`` (docs/model.md §8).

Widths keep the robot touching both sides: at touchdown a leg reaches ``zeta0 cos psi0`` across
(at most 0.95 cos 20° ≈ 0.89 ``l0`` for the controls in use, ``zeta0 <= 0.95``, ``psi0 >= 20°``),
so a chute must stay wider than twice that, ≈ 1.79 ``l0``, for the body to fly between the sides.

>>> world = named_world("narrowing", 2.42)
>>> [round(world.right.x_at(y) - world.left.x_at(y), 3) for y in (0.0, CHUTE_HEIGHT)]
[2.42, 1.815]
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from types import MappingProxyType

import numpy as np

from sim_core.model.errors import ParameterError
from sim_core.model.presets import PRESETS
from sim_core.model.validation import check_range
from sim_core.world.files import read_document, world_from_document
from sim_core.world.footholds import foothold_side, holds_below
from sim_core.world.validation import check_world
from sim_core.world.world import Side, World, parallel

PAPER_L0_M = PRESETS["paper"].leg_length  # [m], 0.54 / 2.42 (docs/model.md §1)
PAPER_D_HAT = PRESETS["paper"].to_model().d_hat  # 2.42
TABLE_HEIGHT_M = 2.0  # the lab's table [m]
CHUTE_HEIGHT = TABLE_HEIGHT_M / PAPER_L0_M  # [l0], ≈ 8.96

# 0.75 rather than 0.7: at 0.7 d_hat (1.69 l0 for the paper) a leg at zeta0 0.95, psi0 20° would
# reach past the chute's middle; 0.75 d_hat (1.815 l0) stays wider than two such legs (1.79 l0).
NARROWING_TOP = 0.75
WIDENING_TOP = 1.3

# The staircase's steps [l0, deg]: each about a jump's rise tall, facing upward, with a stretch
# without grip between them about as tall again; the right side's steps half a period above the left's.
STEP_LENGTH = 0.3
STEP_INCLINE_DEG = 20.0
STEP_GAP = 0.25


@dataclass(frozen=True)
class NamedWorld:
    """A world every tool knows by name: ``build(d_hat)`` makes it for the model's wall distance
    ``d_hat`` [l0]; ``description`` says what it is, for people."""

    build: Callable[[float], World]
    description: str


def tapered(d_hat: float, top_width: float, name: str) -> World:
    """Straight walls from ``d_hat`` apart at the floor to ``top_width`` [l0] apart at
    :data:`CHUTE_HEIGHT`, symmetric about the centre line, with the model's ``mu``."""
    left = Side(np.array([[-d_hat / 2, 0.0], [-top_width / 2, CHUTE_HEIGHT]]), np.array([math.nan]))
    right = Side(np.array([[d_hat / 2, 0.0], [top_width / 2, CHUTE_HEIGHT]]), np.array([math.nan]))
    return World(left, right, name)


def staircase(d_hat: float) -> World:
    """Upward-facing steps with the model's ``mu`` (:data:`STEP_LENGTH`, :data:`STEP_INCLINE_DEG`)
    joined by stretches without grip (:data:`STEP_GAP`) on both sides up to :data:`CHUTE_HEIGHT`,
    centred on the walls ``x = ∓d_hat/2``; the right side's steps start half a period up."""
    beta = math.radians(STEP_INCLINE_DEG)
    period = STEP_LENGTH * math.cos(beta) + STEP_GAP
    sides = []
    for name, start in (("left", 0.0), ("right", period / 2)):
        most = math.ceil(CHUTE_HEIGHT / period)
        lengths, betas, gaps = np.full(most, STEP_LENGTH), np.full(most, beta), np.full(most, STEP_GAP)
        steps = holds_below(lengths, betas, gaps, CHUTE_HEIGHT, start)
        mu = np.full(steps, math.nan)
        wall_x = -d_hat / 2 if name == "left" else d_hat / 2
        side = foothold_side(
            name, wall_x, lengths[:steps], betas[:steps], mu, gaps[: steps - 1], start=start, top=CHUTE_HEIGHT
        )
        sides.append(side)
    return World(*sides, "staircase")


NAMED_WORLDS = MappingProxyType(
    {
        "parallel": NamedWorld(
            lambda d_hat: parallel(d_hat, CHUTE_HEIGHT),
            "The paper's chute: two vertical walls d_hat apart with the model's mu (docs/model.md §2).",
        ),
        "narrowing": NamedWorld(
            lambda d_hat: tapered(d_hat, NARROWING_TOP * d_hat, "narrowing"),
            f"Straight walls leaning in: d_hat apart at the floor, {NARROWING_TOP} d_hat at 2 m, the model's mu.",
        ),
        "widening": NamedWorld(
            lambda d_hat: tapered(d_hat, WIDENING_TOP * d_hat, "widening"),
            f"Straight walls leaning out: d_hat apart at the floor, {WIDENING_TOP} d_hat at 2 m, the model's mu.",
        ),
        "staircase": NamedWorld(
            staircase,
            f"Steps {STEP_LENGTH} l0 long facing {STEP_INCLINE_DEG:g}° upward with the model's mu, {STEP_GAP} l0 "
            "without grip (mu 0) between them, on both walls d_hat apart; the right wall's steps half a period higher.",
        ),
    }
)


def named_world(name: str, d_hat: float) -> World:
    """The named world ``name`` for wall distance ``d_hat`` [l0]; an unknown name is a
    :class:`ParameterError` that lists the known ones."""
    if name not in NAMED_WORLDS:
        raise ParameterError("world", f"unknown world {name!r}; named worlds: {', '.join(NAMED_WORLDS)}")
    check_range("d_hat", d_hat, 0.0)
    try:
        return check_world(NAMED_WORLDS[name].build(d_hat))
    except ParameterError as error:
        raise ParameterError("d_hat", f"{d_hat:g} is too narrow for the {name} world: {error}") from None


def resolve_world(spec: str, d_hat: float, l0_m: float | None = None) -> tuple[World, str]:
    """The world and its description that ``spec`` means: a name in :data:`NAMED_WORLDS`, built for
    ``d_hat`` [l0], else the world file at that path (in metres converted with ``l0_m`` [m])."""
    if spec in NAMED_WORLDS:
        return named_world(spec, d_hat), NAMED_WORLDS[spec].description
    path = Path(spec)
    if not (path.suffix or path.exists() or len(path.parts) > 1):
        raise ParameterError(
            "world", f"{spec!r} is neither a named world ({', '.join(NAMED_WORLDS)}) nor a world file (.json)"
        )
    document = read_document(path)
    return world_from_document(document, l0_m, default_name=path.stem), document.get("description", "")
