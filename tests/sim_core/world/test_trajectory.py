"""Sampled paths in a world: on parallel walls the map's path sample for sample; in a world each
stance's foot on its side's polyline and the path through every touchdown of the climb."""

import math

import numpy as np
import pytest

from sim_core import ControlSchedule
from sim_core.model.trajectory import simulate_trajectory
from sim_core.world.climb import climb_world
from sim_core.world.named import named_world
from sim_core.world.trajectory import simulate_world_trajectory
from sim_core.world.world import parallel

GAIT = ControlSchedule.from_degrees([(30, 0.87), (30, 0.9)])


def test_on_parallel_walls_it_is_the_maps_path(paper):
    ours, climb = simulate_world_trajectory(paper, parallel(paper.d_hat), GAIT, (-1.2, 0.3), 12)
    theirs = simulate_trajectory(paper, GAIT, (-1.2, 0.3), 12, start_height=0.87 * math.sin(math.radians(30)))
    assert climb.failure is None and ours.failure is None
    for name in ours.COLUMNS:
        assert getattr(ours, name) == pytest.approx(getattr(theirs, name), abs=1e-9), name
    assert ours.section_states == pytest.approx(theirs.section_states, abs=1e-10)
    assert ours.rises == pytest.approx(theirs.rises, abs=1e-10)
    assert ours.touchdown_times == pytest.approx(theirs.touchdown_times, abs=1e-10)


@pytest.mark.parametrize("name", ["narrowing", "widening"])
def test_in_a_world_each_stance_stands_on_its_side_and_the_path_meets_every_touchdown(paper, name):
    world = named_world(name, paper.d_hat)
    path, climb = simulate_world_trajectory(paper, world, GAIT, (-1.0, 0.5), 15, sample_rate=400)
    expected = climb_world(paper, world, GAIT, (-1.0, 0.5), 15)
    assert np.array_equal(climb.states, expected.states) and climb.failure == expected.failure
    stance = path.phase == 0
    sides = np.where(path.foot_x[stance] < 0, "left", "right")
    on_side = [world.side(side).x_at(y) for side, y in zip(sides, path.foot_y[stance], strict=True)]
    assert path.foot_x[stance] == pytest.approx(on_side, abs=1e-12)
    for k, when in enumerate(path.touchdown_times[1:], start=1):
        nearest = int(np.argmin(np.abs(path.time - when)))
        assert abs(path.time[nearest] - when) <= 1 / 400
        step = abs(path.time[nearest] - when) * 3.0  # the body moves < 3 l0 per unit time here
        assert path.x[nearest] == pytest.approx(climb.states[k, 0], abs=step + 1e-9)
        assert path.y[nearest] == pytest.approx(climb.states[k, 1], abs=step + 1e-9)
