"""One jump's kernel and the orbit kernels: statuses, returned slots, and the buffers they fill.

The map's accuracy over many jumps is test_poincare.py's (against the Cartesian reference);
here the kernels are called directly, as :mod:`sim_core.model.poincare` calls them.
"""

import math
from dataclasses import replace

import numpy as np
import pytest
from numpy.testing import assert_allclose

from sim_core import ControlSchedule, LegControl, iterate_map, iterate_map_batch
from sim_core.model.failures import COLLAPSE, INVALID_STATE, NO_FLIGHT, NO_LIFTOFF, OK, SLIP
from sim_core.model.integrate import PSI, PSI_DOT, STANCE_TIME_CAP, STATE_SIZE, TIME, ZETA, ZETA_DOT
from sim_core.model.reference import reference_jump
from sim_core.model.stride import (
    jump,
    lift_off,
    liftoff_velocity,
    orbit,
    orbit_batch,
    scheduled_jump,
    touchdown_polar_state,
)

ATOL_REFERENCE = 1e-8  # kernel vs scipy DOP853 at rtol = atol = 1e-11 (as test_reference.py)
REFERENCE_TOLERANCES = {"rtol": 1e-11, "atol": 1e-11}
FLIGHT_ENERGY_RTOL = 1e-12  # the flight is closed-form: only rounding separates the two sides
ROUND_TRIP_ATOL = 1e-14

START = (-0.93, -0.17)
LEG = LegControl.from_degrees(30.0, 0.9)
NO_RECORD = np.empty((0, STATE_SIZE))


def _jump(model, state, leg=LEG, next_leg=LEG, record=NO_RECORD):
    """``jump`` as poincare calls it: ``(status, next_xdot, next_ydot, rise, stance, flight, rows)``."""
    return jump(state[0], state[1], leg.psi0, leg.zeta0, next_leg.psi0, next_leg.zeta0, model.record(), record)


def test_successful_jump_fills_every_slot(paper):
    record = np.empty((500, STATE_SIZE))
    status, next_xdot, next_ydot, rise, stance_time, flight_time, rows = _jump(paper, START, record=record)
    assert status == OK
    assert next_xdot < 0, "after the flip the body again flies toward the (left) wall"
    assert all(math.isfinite(v) for v in (next_ydot, rise, stance_time, flight_time))
    assert stance_time > 0 and flight_time > 0 and rise > 0, "the paper's gait climbs"
    assert 2 < rows < record.shape[0], "touchdown, the accepted steps and the lift-off"
    assert record[0, ZETA] == LEG.zeta0 and record[0, PSI] == LEG.psi0 and record[0, TIME] == 0.0
    assert record[rows - 1, ZETA] == 1.0 and record[rows - 1, TIME] == stance_time, "the last row is the lift-off"


def test_flight_is_ballistic_from_the_recorded_liftoff(paper):
    """What the kernel returns after the stance is the closed-form flight of docs/model.md §2."""
    right = LegControl.from_degrees(34.0, 0.88)
    record = np.empty((500, STATE_SIZE))
    status, next_xdot, next_ydot, rise, _, flight_time, rows = _jump(paper, START, LEG, right, record)
    assert status == OK
    liftoff = record[rows - 1]
    vx, vy = liftoff_velocity(liftoff[PSI], liftoff[ZETA_DOT], liftoff[PSI_DOT])
    assert next_xdot == -vx, "the flip mirrors x only"
    distance = paper.d_hat - math.cos(liftoff[PSI]) - right.zeta0 * math.cos(right.psi0)
    assert flight_time == pytest.approx(distance / vx, rel=FLIGHT_ENERGY_RTOL)
    # Energy per unit mass, heights above this jump's foot: kinetic + y is conserved in flight.
    at_liftoff = 0.5 * (vx**2 + vy**2) + math.sin(liftoff[PSI])
    at_touchdown = 0.5 * (next_xdot**2 + next_ydot**2) + rise + right.zeta0 * math.sin(right.psi0)
    assert at_touchdown == pytest.approx(at_liftoff, rel=FLIGHT_ENERGY_RTOL)


def test_lift_off_is_the_jumps_own_stance(paper):
    """lift_off ends where jump's stance ends: the recorded lift-off row, the same stance time, and
    the same failure with the stance time kept; an invalid state fails before any stance."""
    record = np.empty((500, STATE_SIZE))
    status, psi, vx, vy, stance_time, rows = lift_off(*START, LEG.psi0, LEG.zeta0, paper.record(), record)
    assert status == OK and record[rows - 1, PSI] == psi
    assert (vx, vy) == liftoff_velocity(psi, record[rows - 1, ZETA_DOT], record[rows - 1, PSI_DOT])
    assert stance_time == _jump(paper, START)[4]
    slipping = LegControl.from_degrees(70.0, 0.9)
    failed = lift_off(*START, slipping.psi0, slipping.zeta0, paper.record(), NO_RECORD)
    assert failed[0] == SLIP == _jump(paper, START, slipping)[0] and math.isnan(failed[1])
    assert lift_off(0.1, -0.2, LEG.psi0, LEG.zeta0, paper.record(), NO_RECORD)[0] == INVALID_STATE


@pytest.mark.parametrize(
    ("state", "leg", "next_leg"),
    [
        (START, LEG, LEG),
        ((-0.8, -0.2), LegControl.from_degrees(30.0, 0.87), LEG),
        ((-0.9, 0.1), LEG, LegControl.from_degrees(35.0, 0.88)),
        ((-0.1, -2.5), LEG, LEG),  # a steep fall: the leg passes over the foot
    ],
)
def test_jump_agrees_with_the_scipy_reference(paper, state, leg, next_leg):
    status, next_xdot, next_ydot, rise, *_ = _jump(paper, state, leg, next_leg)
    expected = reference_jump(paper, state, leg, next_leg, **REFERENCE_TOLERANCES)
    assert status == expected[0] == OK
    assert_allclose([next_xdot, next_ydot, rise], expected[1:], rtol=0, atol=ATOL_REFERENCE, err_msg="one jump")


STANCE_FAILURES = [
    # (status, model overrides, leg in degrees, start): each fails during its first stance
    (SLIP, {"mu": math.tan(math.radians(31.0))}, (30.0, 0.9), (-0.95, -0.1)),
    (COLLAPSE, {"alpha": 0.2, "c_zeta": 0.0, "c_psi": 0.0, "mu": math.inf}, (45.0, 0.3), (-7.07, -7.07)),
    (NO_LIFTOFF, {"c_zeta": 20.0, "c_psi": 20.0, "mu": math.inf}, (30.0, 0.9), (-0.5, -0.1)),
    (NO_FLIGHT, {}, (30.0, 0.9), (-0.3, 5.0)),  # lifts off heading away from the other wall
    (NO_FLIGHT, {"d_hat": 1.5, "mu": math.inf}, (20.0, 0.9), (-0.9, -0.1)),  # the next foot is already there
]


@pytest.mark.parametrize(("expected", "overrides", "leg_deg", "state"), STANCE_FAILURES)
def test_failures_keep_only_the_stance_time(paper, expected, overrides, leg_deg, state):
    model = replace(paper, **overrides)
    leg = LegControl.from_degrees(*leg_deg)
    record = np.empty((500, STATE_SIZE))
    status, next_xdot, next_ydot, rise, stance_time, flight_time, rows = _jump(model, state, leg, leg, record)
    assert status == expected
    assert all(math.isnan(v) for v in (next_xdot, next_ydot, rise, flight_time))
    assert 0 < stance_time <= STANCE_TIME_CAP and rows >= 1
    assert record[rows - 1, TIME] == stance_time, "the stance is recorded up to where it ended"
    if expected == NO_LIFTOFF:
        assert stance_time == STANCE_TIME_CAP
    assert reference_jump(model, state, leg, leg, **REFERENCE_TOLERANCES)[0] == expected, "scipy agrees"


@pytest.mark.parametrize(
    ("state", "next_zeta0"),
    [
        ((0.0, 0.0), 0.9),  # not flying toward the wall
        ((0.4, -0.1), 0.9),
        ((math.nan, 0.0), 0.9),
        ((-0.9, math.inf), 0.9),
        (START, 1.0),  # the next leg's length is outside (0, 1)
        (START, 0.0),
        (START, math.nan),
    ],
)
def test_invalid_inputs_fail_before_any_stance(paper, state, next_zeta0):
    record = np.full((10, STATE_SIZE), 7.0)
    result = jump(state[0], state[1], LEG.psi0, LEG.zeta0, LEG.psi0, next_zeta0, paper.record(), record)
    status, *numbers, rows = result
    assert status == INVALID_STATE and rows == 0
    assert all(math.isnan(v) for v in numbers), "no stance was integrated: every number is NaN"
    assert (record == 7.0).all(), "nothing recorded"


@pytest.mark.parametrize(("xdot", "ydot", "psi0_deg"), [(-0.93, -0.17, 30.0), (-1.5, 0.8, 45.0), (-0.2, -1.0, 20.0)])
def test_polar_and_cartesian_rates_invert_at_full_length(xdot, ydot, psi0_deg):
    """At ``zeta = 1`` the touchdown and lift-off conversions are each other's inverse."""
    psi = math.radians(psi0_deg)
    zeta_dot, psi_dot = touchdown_polar_state(xdot, ydot, psi, 1.0)
    assert_allclose(liftoff_velocity(psi, zeta_dot, psi_dot), (xdot, ydot), rtol=0, atol=ROUND_TRIP_ATOL)


def test_scheduled_jumps_use_rows_k_and_k_plus_one_cyclically(paper):
    schedule = ControlSchedule.from_degrees([(30.0, 0.87), (34.0, 0.9), (28.0, 0.88)])
    array, model = schedule.as_array(), paper.record()
    state = START
    for k in range(5):
        this, following = schedule[k], schedule[k + 1]
        direct = _jump(paper, state, this, following)
        scheduled = scheduled_jump(state[0], state[1], array, k, model, NO_RECORD)
        assert scheduled == direct[:4], f"jump {k}"
        state = scheduled[1:3]


def test_chained_jumps_are_iterate_map(paper, alternating):
    """The map applies the same kernel: chaining jumps by hand gives its states to the bit."""
    expected = iterate_map(paper, alternating, START, 6, first_jump=1)
    array, state = alternating.as_array(), START
    for k in range(6):
        status, xdot, ydot, rise = scheduled_jump(state[0], state[1], array, 1 + k, paper.record(), NO_RECORD)
        assert status == OK
        state = (xdot, ydot)
        assert state == tuple(expected.states[k + 1]) and rise == expected.rises[k], f"jump {k + 1}"


def _orbit_buffers(jumps: int):
    """Output buffers filled with garbage the kernel must overwrite."""
    return np.full((jumps + 1, 2), 99.0), np.full(jumps, 99.0)


def test_orbit_fills_its_buffers(paper, symmetric):
    states, rises = _orbit_buffers(5)
    status, completed = orbit(*START, symmetric.as_array(), 0, paper.record(), states, rises)
    assert (status, completed) == (OK, 5)
    assert tuple(states[0]) == START and np.isfinite(states).all() and np.isfinite(rises).all()
    assert (states[1:, 0] < 0).all()


def test_orbit_marks_what_follows_a_failure(paper):
    """psi0 = 45°, zeta0 = 0.8/0.9 climbs three jumps and then has no flight."""
    schedule = ControlSchedule.from_degrees([(45.0, 0.8), (45.0, 0.9)])
    states, rises = _orbit_buffers(8)
    status, completed = orbit(*START, schedule.as_array(), 0, paper.record(), states, rises)
    assert (status, completed) == (NO_FLIGHT, 3), "on failure, jump `completed` (0-based) failed"
    assert np.isfinite(states[: completed + 1]).all() and np.isfinite(rises[:completed]).all()
    assert np.isnan(states[completed + 1 :]).all() and np.isnan(rises[completed:]).all()
    mapped = iterate_map(paper, schedule, START, 8)
    assert mapped.failed_jump == completed + 1
    assert_allclose(mapped.states, states[: completed + 1], rtol=0, atol=0)


def test_orbit_of_zero_jumps_keeps_the_start(paper, symmetric):
    states, rises = _orbit_buffers(0)
    assert orbit(*START, symmetric.as_array(), 0, paper.record(), states, rises) == (OK, 0)
    assert tuple(states[0]) == START


def test_orbit_batch_shares_or_splits_schedules(paper, symmetric):
    starts = np.array([START, (0.5, 0.0), (-0.8, -0.2)])
    schedules = np.stack([ControlSchedule.from_degrees([(30.0, z)]).as_array() for z in (0.85, 0.9, 0.95)])
    for given in (symmetric.as_array()[np.newaxis], schedules):
        states, rises = np.empty((3, 5, 2)), np.empty((3, 4))
        status, completed = np.empty(3, dtype=np.int64), np.empty(3, dtype=np.int64)
        orbit_batch(starts, given, 0, paper.record(), states, rises, status, completed)
        assert list(status) == [OK, INVALID_STATE, OK] and list(completed) == [4, 0, 4]
        for i in (0, 2):
            single_states, single_rises = _orbit_buffers(4)
            schedule = given[0] if given.shape[0] == 1 else given[i]
            orbit(*starts[i], schedule, 0, paper.record(), single_states, single_rises)
            assert_allclose(states[i], single_states, rtol=0, atol=0, err_msg=f"start {i}")
        assert np.isnan(states[1, 1:]).all() and tuple(states[1, 0]) == (0.5, 0.0)
    batch = iterate_map_batch(paper, schedules, starts, 4)
    assert_allclose(batch.states, states, rtol=0, atol=0, err_msg="the wrapper adds nothing to the numbers")
