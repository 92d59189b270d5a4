"""The compiled SLIP step (sim_core/viability/slip_hopper.py) against an independent scipy twin of the same model.

The twin is written here from the model's equations (foot at the origin, flight in closed form,
stance by ``solve_ivp`` with events), not from the kernel, and shares nothing with it but
:class:`SlipHopper`'s numbers. vibly itself is not needed (scripts/vibly_crosscheck.py compares
with it).
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from numpy.testing import assert_allclose
from scipy.integrate import solve_ivp

from sim_core.model.errors import ParameterError
from sim_core.viability.slip_hopper import SlipHopper, SlipOutcome, slip_outcomes, slip_step, slip_step_map

RTOL_TWIN = 1e-10  # the twin's DOP853 tolerance
ATOL_NEXT_STATE = 1e-9  # |s' - s'_twin| allowed [-]: the RK4 stance is ~1e-11 off

# (s, angle of attack [deg]) -> the outcome the twin gives, over every way of failing the default grid shows
CASES = [
    (0.45, 30.0, SlipOutcome.APEX),
    (0.45, 40.0, SlipOutcome.APEX),
    (0.30, 50.0, SlipOutcome.APEX),
    (0.75, 30.0, SlipOutcome.APEX),  # lands near the top of the range (s' ~ 0.998)
    (0.90, 10.0, SlipOutcome.APEX),
    (0.15, 0.0, SlipOutcome.INFEASIBLE),  # the apex is lower than the leg
    (1.20, 30.0, SlipOutcome.INFEASIBLE),  # more height than the energy allows
    (0.30, 70.0, SlipOutcome.FALL),  # a flat leg: the body reaches the ground in stance
    (0.60, 40.0, SlipOutcome.REVERSAL),  # bounces backward
    (0.15, 70.0, SlipOutcome.REVERSAL),
    (0.60, 0.0, SlipOutcome.NO_APEX),  # a vertical leg at speed: lifts off heading down
]


def twin_step(hopper: SlipHopper, s: float, aoa: float) -> tuple[SlipOutcome, float]:
    """One apex-to-apex step of the SLIP: ``(outcome, s')``, with the foot at the origin in stance."""
    m, k, l0, g, energy = hopper.mass, hopper.stiffness, hopper.resting_length, hopper.gravity, hopper.total_energy
    if not 0.0 <= s <= 1.0:
        return SlipOutcome.INFEASIBLE, np.nan
    height, speed = energy * s / (m * g), np.sqrt(2.0 * energy * (1.0 - s) / m)
    foot_height = height - l0 * np.cos(aoa)
    if foot_height < 0.0:
        return SlipOutcome.INFEASIBLE, np.nan

    def rates(_t, z):
        length = np.hypot(z[0], z[1])
        along = k / m * (l0 - length) / length
        return [z[2], z[3], along * z[0], along * z[1] - g]

    def touched_ground(_t, z):
        return z[1]

    def lifted_off(_t, z):
        return np.hypot(z[0], z[1]) - l0

    def ran_back(_t, z):
        return z[2] + 1e-5

    for event, direction in ((touched_ground, -1), (lifted_off, 1), (ran_back, -1)):
        event.terminal, event.direction = True, direction
    touchdown = [-l0 * np.sin(aoa), l0 * np.cos(aoa), speed, -np.sqrt(2.0 * g * foot_height)]
    stance = solve_ivp(
        rates,
        (0.0, hopper.max_time),
        touchdown,
        method="DOP853",
        rtol=RTOL_TWIN,
        atol=1e-12,
        events=(touched_ground, lifted_off, ran_back),
    )
    if stance.t_events[0].size:
        return SlipOutcome.FALL, np.nan
    if stance.t_events[2].size:
        return SlipOutcome.REVERSAL, np.nan
    _, y, xdot, ydot = stance.y[:, -1]
    if ydot < 0.0:
        return SlipOutcome.NO_APEX, np.nan
    apex = y + ydot**2 / (2.0 * g)
    if xdot <= 0.0:
        return SlipOutcome.BACKWARD, np.nan
    return SlipOutcome.APEX, g * apex / (g * apex + xdot**2 / 2.0)


def _columns(cases):
    states = np.array([[s] for s, _, _ in cases])
    actions = np.radians([[degrees] for _, degrees, _ in cases])
    return states, actions


def test_outcomes_and_next_states_match_the_scipy_twin():
    hopper = SlipHopper()
    states, actions = _columns(CASES)
    reached, outcomes = slip_outcomes(states, actions, hopper)
    for row, (s, degrees, expected) in enumerate(CASES):
        outcome, s_next = twin_step(hopper, s, np.radians(degrees))
        assert outcome == expected, f"the twin's outcome at s={s}, aoa={degrees} deg (the case table is stale)"
        assert SlipOutcome(outcomes[row]) == expected, f"outcome at s={s}, aoa={degrees} deg"
        assert_allclose(reached[row, 0], s_next, atol=ATOL_NEXT_STATE, err_msg=f"s' at s={s}, aoa={degrees} deg")


def test_another_hopper_matches_its_twin():
    hopper = dataclasses.replace(SlipHopper(), stiffness=12_000.0, total_energy=2000.0)
    states, actions = np.array([[0.5], [0.7], [0.6]]), np.radians([[28.0], [20.0], [45.0]])
    reached, outcomes = slip_outcomes(states, actions, hopper)
    for row in range(states.shape[0]):
        outcome, s_next = twin_step(hopper, states[row, 0], actions[row, 0])
        assert SlipOutcome(outcomes[row]) == outcome, f"row {row}"
        assert_allclose(reached[row, 0], s_next, atol=ATOL_NEXT_STATE, err_msg=f"s' of row {row}")


def test_step_map_contract():
    states, actions = _columns(CASES)
    reached, failed = slip_step(states, actions)
    assert reached.shape == (len(CASES), 1) and reached.dtype == np.float64
    assert failed.shape == (len(CASES),) and failed.dtype == bool
    expected_failed = np.array([outcome != SlipOutcome.APEX for _, _, outcome in CASES])
    np.testing.assert_array_equal(failed, expected_failed)
    assert np.all(np.isfinite(reached[~failed])) and np.all(np.isnan(reached[failed]))
    mapped, mapped_failed = slip_step_map(SlipHopper())(states, actions)
    np.testing.assert_array_equal(mapped, reached)
    np.testing.assert_array_equal(mapped_failed, failed)


def test_bad_input_is_refused():
    with pytest.raises(ValueError, match=r"\(N, 1\)"):
        slip_step(np.zeros((3, 2)), np.zeros((3, 1)))
    with pytest.raises(ParameterError, match="stiffness"):
        SlipHopper(stiffness=-1.0)
    assert SlipOutcome.REVERSAL.message
