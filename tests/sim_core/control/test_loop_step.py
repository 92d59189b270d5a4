"""One jump of a closed loop from its whole state (sim_core/control/loop_step.py): the state array holds
everything the next jumps depend on, and a run that comes down to the floor ends there."""

import math

import numpy as np
import pytest

from experiments.control_study import Config, laws_for
from sim_core.control.loop_step import FOOT, LOOP_STATE_SIZE, body_height, loop_jump, start_loop
from sim_core.model.failures import FLOOR, OK
from sim_core.model.integrate import STATE_SIZE
from sim_core.model.noise import NO_NOISE, NoiseModel
from sim_core.model.noise_rules import seed_trial
from sim_core.model.presets import get_preset

ROBOT = get_preset("paper")
NOISE = NoiseModel(velocity=0.02, pitch_drift_deg=0.0)


@pytest.fixture(scope="module", params=["pid", "lqr"])
def climb_and_law(request):
    loop, (law,) = laws_for(ROBOT.to_model(), Config(controllers=(request.param,)), ROBOT.leg_length)
    return loop, law


def _run(state, k0, law, noise, seed, jumps):
    """``jumps`` jumps from touchdown ``k0``, seeded once: the states reached."""
    kind, parameters = law.kernel_args()
    seed_trial(seed)
    states, no_record = [], np.empty((0, STATE_SIZE))
    for k in range(k0, k0 + jumps):
        status, _ = loop_jump(state, k, kind, parameters, noise.record(), ROBOT.to_model().record(),
                              no_record)  # fmt: skip
        assert status == OK
        states.append(state.copy())
    return np.array(states)


def test_a_copied_state_continues_as_the_original_whatever_ran_between(climb_and_law):
    """Splitting copies a run's state and continues it: nothing the next jumps use lives outside
    the array (the law's memory, the pitch, the controls in flight are in it)."""
    loop, law = climb_and_law
    kind = law.kernel_args()[0]
    state = np.empty(LOOP_STATE_SIZE)
    seed_trial(5)
    start_loop(state, kind, *loop.start, math.radians(law.psi0_deg), 0.9, NOISE.record())
    _run(state, 0, law, NOISE, 6, 30)
    copy = state.copy()
    first = _run(state, 30, law, NOISE, 7, 40)
    _run(np.array(copy), 30, law, NOISE, 8, 25)  # something else in between, from the same point
    again = _run(copy, 30, law, NOISE, 7, 40)
    np.testing.assert_array_equal(first, again)


def test_a_run_that_comes_down_below_the_floor_ends_there(climb_and_law):
    loop, law = climb_and_law
    kind, parameters = law.kernel_args()
    state = np.empty(LOOP_STATE_SIZE)
    start_loop(state, kind, *loop.start, math.radians(law.psi0_deg), 0.9, NO_NOISE.record())
    arguments = (NO_NOISE.record(), ROBOT.to_model().record(), np.empty((0, STATE_SIZE)))
    high, low = state.copy(), state.copy()
    high[FOOT] = 0.0
    assert loop_jump(high, 0, kind, parameters, *arguments)[0] == OK and body_height(high) > 0
    low[FOOT] = -body_height(state) - 2.0  # two leg lengths below: no jump climbs that
    assert loop_jump(low, 0, kind, parameters, *arguments)[0] == FLOOR
