"""One-jump predictions of tracked touchdowns in a world (sim_core.calibration.world_jumps): on a
world of two vertical sides ``d_hat`` apart they are the parallel-walls predictions
(calibrate.one_jump_predictions) to rounding — offsets, pitch and the detector's shifts included —
and in a world whose sides lean, they give a world climb's touchdowns back."""

import numpy as np
import pytest
from numpy.testing import assert_allclose

from sim_core import ControlSchedule, LegControl, iterate_map
from sim_core.calibration.calibrate import one_jump_predictions
from sim_core.calibration.touchdown_series import TouchdownSeries
from sim_core.calibration.world_jumps import world_one_jump_predictions
from sim_core.model.controls import NO_OFFSETS, LegOffsets
from sim_core.world.climb import climb_world, section_orbit
from sim_core.world.named import named_world
from sim_core.world.world import parallel

GAIT = ControlSchedule.from_degrees([(30, 0.87), (30, 0.9)])
OFFSETS = LegOffsets(psi0_offset_deg=(0.6, -0.8), zeta0_offset=(0.004, -0.005))
TIGHT = 1e-9


def series_of(states, feet, legs, *, right_first: bool, pitch=None) -> TouchdownSeries:
    n = len(states)
    return TouchdownSeries.of(
        state=states,
        foot_height=feet,
        commanded=[(leg.psi0, leg.zeta0) for leg in legs],
        right_leg=[(k % 2 == 1) != right_first for k in range(n)],
        pitch=pitch,
    )


def noisy_gait_series(paper, rng, *, right_first: bool) -> TouchdownSeries:
    """Twelve touchdowns near the gait's orbit, each state, foot and pitch a little off."""
    orbit = iterate_map(paper, GAIT, (-0.95, 0.1), 11)
    states = orbit.states + rng.normal(0.0, 0.01, orbit.states.shape)
    feet = np.r_[0.0, np.cumsum(orbit.rises)] + 2.0 + rng.normal(0.0, 0.005, 12)
    legs = [GAIT[k] for k in range(12)]
    return series_of(states, feet, legs, right_first=right_first, pitch=rng.normal(0.0, 0.02, 12))


@pytest.mark.parametrize("right_first", [False, True])
def test_on_vertical_sides_it_is_the_parallel_walls_prediction(paper, right_first):
    series = noisy_gait_series(paper, np.random.default_rng(4), right_first=right_first)
    models = {"paper": (paper, NO_OFFSETS), "offset": (paper, OFFSETS)}
    walls = one_jump_predictions(series, models)
    world = world_one_jump_predictions(series, models, parallel(paper.d_hat))
    assert world["index"] == walls["index"] == list(range(1, 12))
    assert_allclose(world["measured"], walls["measured"], rtol=0, atol=0)
    for name in models:
        assert np.isfinite(walls[name]).all()
        assert_allclose(world[name], walls[name], rtol=0, atol=TIGHT, err_msg=name)
    moved = np.abs(walls["offset"] - walls["paper"]).max()
    assert moved > 1e-3, f"the offsets and the detector's shifts change the prediction ({moved:.2e})"


def test_in_a_leaning_world_it_gives_the_climb_s_touchdowns_back(paper):
    world = named_world("narrowing", paper.d_hat)
    climb = climb_world(paper, world, GAIT, (-1.0, 0.5), 7)
    assert climb.failure is None
    orbit = section_orbit(climb, GAIT)
    feet = np.r_[0.0, np.cumsum(orbit.rises)]
    legs = [GAIT[k] for k in range(8)]
    series = series_of(orbit.states[1:], feet[1:], legs[1:], right_first=True)
    found = world_one_jump_predictions(series, {"paper": (paper, NO_OFFSETS)}, world)
    assert_allclose(found["paper"], found["measured"], rtol=0, atol=TIGHT)
    walls = one_jump_predictions(series, {"paper": (paper, NO_OFFSETS)})
    assert np.nanmax(np.abs(walls["paper"] - walls["measured"])) > 0.01, "the parallel walls are not this world"


def test_a_jump_that_fails_or_a_leg_out_of_its_domain_is_nan(paper):
    steep = LegControl.from_degrees(89.9, 0.9)  # turned past 90 degrees by the pitch: no leg
    series = series_of([(-0.95, 0.1), (-0.95, 0.1), (-0.95, 0.1)], [0.0, 0.1, 0.2], [GAIT[0], GAIT[1], steep],
                       right_first=False, pitch=[0.0, 0.0, 0.1])  # fmt: skip
    ice = parallel(paper.d_hat, mu=0.0)  # no grip: the first stance slips
    found = world_one_jump_predictions(series, {"paper": (paper, NO_OFFSETS)}, ice)
    assert np.isnan(found["paper"]).all() and np.isfinite(found["measured"]).all()
