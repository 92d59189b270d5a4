"""The foothold study: open-loop's count is the world trials' on the same seeds with the schedule
the reach search chose; the outcome does not depend on how the chunks are run."""

import numpy as np

from sim_core.model.noise import NoiseModel
from sim_core.planning.study import foothold_study
from sim_core.robustness.world_trials import REACHED, run_world_trials
from sim_core.world.random_world import random_world

START = (-1.0, 0.5)


def _reversed(function, arguments, progress=None):
    """A chunk map that runs the chunks last first (results in order)."""
    results = [function(*chunk) for chunk in reversed(arguments)]
    return results[::-1]


def test_open_loop_is_the_chosen_schedule_on_the_same_seeds_and_chunking_changes_nothing(paper):
    worlds = [(f"random:{seed}", random_world(seed)) for seed in (7, 9)]
    study = foothold_study(paper, worlds, 2.0, START, trials=4, seed=21)
    again = foothold_study(paper, worlds, 2.0, START, trials=4, seed=21, chunk_map=_reversed)
    assert [o.to_dict() for o in study.worlds] == [o.to_dict() for o in again.worlds]
    for (label, world), outcome in zip(worlds, study.worlds, strict=True):
        psi0_deg, zeta0 = outcome.schedule
        schedule = np.array([[np.radians(psi0_deg), zeta0]])
        _, status = run_world_trials(paper, schedule, START, NoiseModel(), 21 + np.arange(4), 200, world, 0.0, 2.0)
        assert outcome.world == label and outcome.reached["open-loop"] == int(np.sum(status == REACHED))
        assert sum(outcome.failures["open-loop"].values()) + outcome.reached["open-loop"] == 4
