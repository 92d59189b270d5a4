"""The AMS loop alone (sim_core/robustness/ams.py), on a walk whose chance is known: a ±1 random
walk from 0 reaches ``top`` before -1 with chance 1 / (top + 1) (gambler's ruin). Its integer
levels tie often, which the loop must handle (all tied paths dropped together)."""

import math

import numpy as np
import pytest

from sim_core.robustness.ams import ams_chance


def _walk(start: list[int], rng, top: int) -> tuple[list[int], float]:
    path = list(start)
    while -1 < path[-1] < top:
        path.append(path[-1] + (1 if rng.random() < 0.5 else -1))
    return path, (math.inf if path[-1] == top else float(max(path)))


@pytest.mark.parametrize("top", [9, 19])
def test_its_chance_is_the_gamblers_ruin(top):
    rng = np.random.default_rng(top)

    def branch(parent, floor):
        path, level = parent
        at = next((i for i, x in enumerate(path) if x > floor), None)
        if at is None:  # passed the level only by failing
            return parent, level
        continued = _walk(path[: at + 1], rng, top)
        return continued, continued[1]

    chances = []
    for _ in range(300):
        paths = [_walk([0], rng, top) for _ in range(20)]
        chances.append(ams_chance(paths, [level for _, level in paths], branch, rng)[0])
    assert np.mean(chances) == pytest.approx(1.0 / (top + 1), rel=0.15)


def test_stopped_early_it_counts_the_share_that_failed():
    rng = np.random.default_rng(0)
    paths = [("failed", math.inf), ("home", 1.0), ("home", 2.0), ("failed", math.inf)]
    chance, passed = ams_chance(paths, [level for _, level in paths], lambda parent, floor: parent, rng, max_levels=0)
    assert (chance, passed) == (0.5, 0)
    tied = [("home", 1.0)] * 3
    assert ams_chance(tied, [1.0] * 3, lambda parent, floor: parent, rng) == (0.0, 0), "all tied: extinct"
