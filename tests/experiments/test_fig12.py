"""Paper Fig. 12 (experiments/fig12.py): a PID on the touchdown height climbs to 55 cm and holds
it, noise-free and with noise; its configuration is checked before any search.

Thirty jumps and one noisy run keep it quick; the full configuration's claims are checked by
tests/experiments/test_reproduce.py (slow).
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from experiments import fig12
from sim_core import ControlSchedule, LegControl, ParameterError, find_fixed_point, get_preset
from sim_core.model.presets import START_GUESS

ROBOT = get_preset("paper")
CONFIG = fig12.Config(jumps=30, noisy_seeds=(1,))
SETTLED = 0.02  # the settling band of ClosedLoopRun.settling_jump: ±2% of the target


@pytest.fixture(scope="module")
def result():
    return fig12.run(ROBOT, CONFIG)


def test_the_noise_free_climb_settles_at_the_target(result):
    heights = result.clean.height * ROBOT.scales.length  # [m] at each touchdown
    assert result.clean.failure is None
    assert heights[0] < 0.5 * CONFIG.target_m, "it starts well below"
    settled = result.clean.settling_jump()
    assert settled is not None and settled < CONFIG.jumps
    np.testing.assert_allclose(heights[settled:], CONFIG.target_m, rtol=SETTLED, err_msg="held from there on")
    assert fig12.claims(result)[0].agrees is True


def test_the_path_is_drawn_in_metres_between_the_walls(result):
    path = result.path
    half_width = 0.5 * ROBOT.wall_distance
    assert np.all(np.abs(path.x) < half_width), "the body stays between the walls"
    assert path.y.max() == pytest.approx(CONFIG.target_m, rel=0.15), "it climbs to about the target [m]"
    last_touchdown = result.clean.time[-1] * ROBOT.scales.time  # [s]
    assert path.time[-1] == pytest.approx(last_touchdown, abs=0.01), "in seconds, to the last touchdown"


def test_the_feed_forward_is_the_zeta0_of_jumping_in_place():
    model = ROBOT.to_model()
    loop = fig12.PidClimb.of(model, CONFIG, ROBOT.leg_length)
    assert CONFIG.zeta0_min < loop.hover < CONFIG.zeta0_max
    hovering = ControlSchedule.of(LegControl.from_degrees(CONFIG.psi0_deg, loop.hover))
    gait = find_fixed_point(model, hovering, 1, START_GUESS)
    assert abs(gait.climb_per_period) < 1e-3, "at the hover zeta0 the gait neither climbs nor descends [l0]"
    assert loop.controller.target == pytest.approx(CONFIG.target_m / ROBOT.leg_length), "the target in l0"


@pytest.mark.parametrize(
    ("change", "field"),
    [({"kp": -1.0}, "kp"), ({"target_m": 0.0}, "target"), ({"jumps": -1}, "jumps"), ({"zeta0_max": 0.8}, "zeta0_max")],
)
def test_a_bad_configuration_is_named_before_any_search(change, field):
    with pytest.raises(ParameterError, match=rf"^{field}:"):
        fig12.PidClimb.of(ROBOT.to_model(), dataclasses.replace(CONFIG, **change), ROBOT.leg_length)


def test_its_table_has_a_column_per_noisy_seed(result):
    table = fig12.table(result)
    assert list(table) == ["touchdown", "time_s", "height_m", "zeta0", "height_m_noise_seed1"]
    assert len(table["height_m"]) == result.clean.height.size == CONFIG.jumps + 1
    assert np.all((table["zeta0"] >= CONFIG.zeta0_min) & (table["zeta0"] <= CONFIG.zeta0_max)), "the PID's limits"
    assert [run["seed"] for run in fig12.data(result)["noisy"]] == [1]
