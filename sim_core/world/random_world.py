"""Random footholds (docs/model.md §8, the paper's future work): "random footholds at different
orientations" as a world — on each side, short gripping segments at random inclinations, lengths
and friction, joined by segments without grip (``mu = 0``) of random rise.

The defaults are geometric choices, not climbing results (whether a gait climbs a world is for the
climb to tell): the paper's chute width (``d_hat`` 2.42) and the lab's 2 m table
(:data:`~sim_core.world.named.CHUTE_HEIGHT`); a jump rises about 0.1-0.5 ``l0``, so holds 0.2-0.4
``l0`` long with 0.1-0.4 ``l0`` without grip between them put about half of each side's height
within grip and a foothold within one or two rises of any point; upward-facing holds (to 30°)
with some facing a little downward (to -10°), friction about the paper's ``mu`` = 2.

>>> a, b = random_world(7), random_world(7)
>>> bool((a.left.points == b.left.points).all() and (a.right.mu == b.right.mu).all())
True
"""

from __future__ import annotations

import math

import numpy as np

from sim_core.model.errors import ParameterError
from sim_core.model.validation import check_range
from sim_core.world.footholds import foothold_side, holds_below
from sim_core.world.named import CHUTE_HEIGHT, PAPER_D_HAT
from sim_core.world.validation import MAX_SEGMENTS, check_world
from sim_core.world.world import SIDES, World

# Each foothold but the last is followed by a segment without grip, and one more may reach the top.
MAX_HOLDS = MAX_SEGMENTS // 2
MAX_INCLINE_DEG = 80.0  # steeper holds would be nearly horizontal ledges: a side must rise along each

INCLINE_DEG = (-10.0, 30.0)
MU = (1.0, 2.0)
GAP = (0.1, 0.4)
HOLD_LENGTH = (0.2, 0.4)


def random_world(
    seed: int,
    holds: int | None = None,
    incline_deg: tuple[float, float] = INCLINE_DEG,
    mu: tuple[float, float] = MU,
    gap: tuple[float, float] = GAP,
    hold_length: tuple[float, float] = HOLD_LENGTH,
    width: float = PAPER_D_HAT,
    height: float = CHUTE_HEIGHT,
) -> World:
    """A chute of random footholds, the same for the same arguments.

    Each side starts with a foothold at the floor (``y = 0``) and goes up: foothold, a stretch
    without grip, foothold, ... Each foothold is centred on its wall line ``x = ∓width/2``, with a
    length, an inclination ``beta`` (docs/model.md §8: the normal's angle, the right side mirrored)
    and a friction coefficient drawn uniformly from their intervals; each stretch without grip rises
    a height drawn from ``gap``. Above the last foothold the side goes on without grip up to
    ``height``. Numbers come from ``numpy.random.default_rng(seed)``, drawn for the most footholds a
    side can have, so the first ``k`` footholds do not depend on ``holds``.

    Args:
        seed: >= 0.
        holds: footholds per side, 1 to :data:`MAX_HOLDS`; ``None``: as many as end below ``height``
            (at least one).
        incline_deg: ``(low, high)`` of ``beta`` [deg], within (-80°, 80°); > 0 faces upward.
        mu: ``(low, high)`` of the footholds' friction coefficients, >= 0.
        gap: ``(low, high)`` of the rise [l0] without grip between footholds, > 0.
        hold_length: ``(low, high)`` of the footholds' lengths [l0], > 0.
        width: the distance [l0] between the wall lines, > 0, wider than two footholds reach.
        height: [l0] the sides' top, > 0 (footholds asked for by ``holds`` may go higher).

    Returns:
        A :class:`~sim_core.world.world.World` in ``l0`` named ``random-SEED``, valid by
        :func:`~sim_core.world.validation.check_world`.
    """
    if isinstance(seed, bool) or not isinstance(seed, int | np.integer) or seed < 0:
        raise ParameterError("seed", f"must be an integer >= 0, got {seed!r}")
    if holds is not None:
        if isinstance(holds, bool) or not isinstance(holds, int | np.integer):
            raise ParameterError("holds", f"must be an integer, got {holds!r}")
        if not 1 <= holds <= MAX_HOLDS:
            raise ParameterError("holds", f"must be in [1, {MAX_HOLDS}] per side (MAX_HOLDS), got {holds}")
    incline = _interval("incline_deg", incline_deg, -MAX_INCLINE_DEG, MAX_INCLINE_DEG)
    friction = _interval("mu", mu, 0.0, math.inf, low_open=False)
    rise = _interval("gap", gap, 0.0, math.inf)
    length = _interval("hold_length", hold_length, 0.0, math.inf)
    height = check_range("height", height, 0.0)
    # A foothold reaches at most half its length times sin|beta| into the chute from its wall line
    # (the segments without grip stay within its ends): the two sides together at most this.
    reach = length[1] * max(abs(math.sin(math.radians(bound))) for bound in incline)
    width = check_range("width", width, 0.0)
    if not width > reach:
        raise ParameterError(
            "width", f"must be > {reach:g} l0 so that footholds on the two sides cannot touch, got {width:g}"
        )
    rng = np.random.default_rng(seed)
    sides = []
    for name in SIDES:
        lengths = rng.uniform(*length, MAX_HOLDS)
        betas = np.radians(rng.uniform(*incline, MAX_HOLDS))
        frictions = rng.uniform(*friction, MAX_HOLDS)
        gaps = rng.uniform(*rise, MAX_HOLDS)
        kept = int(holds) if holds is not None else _fitting(lengths, betas, gaps, height)
        wall_x = -width / 2 if name == "left" else width / 2
        side = foothold_side(name, wall_x, lengths[:kept], betas[:kept], frictions[:kept], gaps[: kept - 1], top=height)
        sides.append(side)
    return check_world(World(*sides, f"random-{seed}"))


def _fitting(lengths: np.ndarray, betas: np.ndarray, gaps: np.ndarray, height: float) -> int:
    """How many footholds end below ``height``: at least one, and an error if even all fit."""
    fitting = holds_below(lengths, betas, gaps, height)
    if fitting == len(lengths):
        raise ParameterError(
            "height", f"{height:g} l0 fits more than MAX_HOLDS = {MAX_HOLDS} footholds per side; lower it or give holds"
        )
    return max(fitting, 1)


def _interval(field: str, pair, low: float, high: float, *, low_open: bool = True) -> tuple[float, float]:
    """``(low, high)`` of ``pair``, each within the bounds, ``low <= high``, else a ParameterError."""
    try:
        first, second = pair
    except (TypeError, ValueError):
        raise ParameterError(field, f"must be a pair (low, high), got {pair!r}") from None
    first = check_range(field, first, low, high, low_open=low_open)
    second = check_range(field, second, low, high, low_open=low_open)
    if first > second:
        raise ParameterError(field, f"must be an interval (low, high) with low <= high, got ({first:g}, {second:g})")
    return first, second
