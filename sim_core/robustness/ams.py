"""Adaptive multilevel splitting (AMS; Cérou & Guyader 2007, in the general form of Bréhier, Gazeau,
Goudenège, Lelièvre & Rousset 2016): the chance that a path reaches a rare set (a failure) before
it ends, with paths of any kind — a closed loop's excursions (:mod:`sim_core.robustness.splitting`),
a plan's attempts (:mod:`sim_core.planning.plan_splitting`).

Each path has a *level*, the largest score it reached (a failure's is infinite). Repeatedly, the
paths at the lowest level are dropped and each replaced by a branch of a random survivor: a copy
cut at its first touchdown past that level and continued with fresh noise (copied whole where it
passed the level only by failing). The chance is the product of the survivors' shares, times the
share of failed paths where it stops before every path has failed. Unbiased whatever the score.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import TypeVar

import numpy as np

Path = TypeVar("Path")


def ams_chance(
    paths: list[Path],
    levels,
    branch: Callable[[Path, float], tuple[Path, float]],
    rng: np.random.Generator,
    max_levels: int | None = None,
) -> tuple[float, int]:
    """``(chance, levels passed)`` from the first ``paths`` and their ``levels``; ``branch(parent,
    floor)`` gives a path and its level: ``parent`` cut at its first touchdown past ``floor`` and
    continued (or ``parent`` itself where it passed ``floor`` only by failing). 0 where every path
    stops at the same level, which no branch can pass. ``paths`` is updated in place. At most
    ``max_levels`` levels (None: until every path has failed)."""
    levels = np.array(levels, dtype=float)
    replicas, log_p, passed = len(paths), 0.0, 0
    while not math.isinf(floor := levels.min()):
        if max_levels is not None and passed >= max_levels:
            return math.exp(log_p) * float(np.isinf(levels).mean()), passed
        dropped = np.flatnonzero(levels <= floor)
        if dropped.size == replicas:
            return 0.0, passed
        log_p += math.log1p(-dropped.size / replicas)
        survivors = np.flatnonzero(levels > floor)
        for i in dropped:
            paths[i], levels[i] = branch(paths[rng.choice(survivors)], floor)
        passed += 1
    return math.exp(log_p), passed
