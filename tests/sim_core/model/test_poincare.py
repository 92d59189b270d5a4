"""The compiled map against the independent Cartesian reference, and its invariants."""

import math

import numpy as np
import pytest
from numpy.testing import assert_allclose

from sim_core import ControlSchedule, Failure, ModelParams, ParameterError, iterate_map, iterate_map_batch
from sim_core.model.failures import OK
from tests.sim_core import cartesian_reference

ATOL_REFERENCE = 1e-8  # issue 3: section states agree to <= 1e-8 over several jumps
ENERGY_RTOL = 1e-9


def _params(model: ModelParams) -> dict:
    return {name: getattr(model, name) for name in ("alpha", "d_hat", "c_zeta", "c_psi", "mu")}


CASES = [
    # (model overrides, schedule in degrees, start state)
    ({}, [(30.0, 0.9)], (-0.95, -0.1)),
    ({}, [(30.0, 0.87), (30.0, 0.9)], (-0.8, -0.2)),
    ({}, [(30.0, 0.9), (35.0, 0.88)], (-0.9, 0.1)),
    ({"alpha": 40.0, "d_hat": 2.2, "c_zeta": 0.1, "c_psi": 0.5, "mu": 1.5}, [(25.0, 0.85)], (-1.0, 0.0)),
    ({"c_zeta": 0.0, "c_psi": 0.0, "mu": math.inf}, [(40.0, 0.92), (28.0, 0.86), (33.0, 0.9)], (-0.9, -0.3)),
]


@pytest.mark.parametrize(("overrides", "schedule_deg", "start"), CASES)
def test_map_agrees_with_cartesian_reference(paper, overrides, schedule_deg, start):
    model = ModelParams(**{**_params(paper), **overrides})
    jumps = 6
    orbit = iterate_map(model, ControlSchedule.from_degrees(schedule_deg), start, jumps)
    reference = cartesian_reference.run(_params(model), schedule_deg, start, jumps)
    assert reference.status == OK and orbit.failure is None
    assert_allclose(
        orbit.states,
        np.array(reference.section_states),
        rtol=0,
        atol=ATOL_REFERENCE,
        err_msg="section states over 6 jumps",
    )
    assert_allclose(orbit.rises, reference.rises, rtol=0, atol=ATOL_REFERENCE, err_msg="height gain per jump")


FAILURE_CASES = [
    ("slip", {"mu": math.tan(math.radians(31.0))}, [(30.0, 0.9)], (-0.95, -0.1)),
    ("slip", {"mu": math.inf}, [(60.0, 0.98)], (-0.1, -2.5)),  # passes over the foot
    ("collapse", {"alpha": 0.2, "c_zeta": 0.0, "c_psi": 0.0, "mu": math.inf}, [(45.0, 0.3)], (-7.07, -7.07)),
    ("no_liftoff", {"c_zeta": 20.0, "c_psi": 20.0, "mu": math.inf}, [(30.0, 0.9)], (-0.5, -0.1)),
    ("no_flight", {"alpha": 2.0, "c_zeta": 5.0, "c_psi": 5.0, "mu": math.inf}, [(5.0, 0.9)], (-0.3, 0.0)),
    ("no_flight", {"d_hat": 1.5, "mu": math.inf}, [(20.0, 0.9)], (-0.9, -0.1)),  # next leg already at the wall
]


@pytest.mark.parametrize(("code", "overrides", "schedule_deg", "start"), FAILURE_CASES)
def test_failure_codes_agree_with_reference(paper, code, overrides, schedule_deg, start):
    model = ModelParams(**{**_params(paper), **overrides})
    orbit = iterate_map(model, ControlSchedule.from_degrees(schedule_deg), start, 3)
    reference = cartesian_reference.run(_params(model), schedule_deg, start, 3)
    assert orbit.failure is not None and orbit.failure.code == code
    assert reference.status == orbit.failure.value
    assert orbit.failed_jump == len(reference.rises) + 1
    assert orbit.to_dict()["failure"] == {"code": code, "jump": orbit.failed_jump}


def test_energy_bookkeeping_without_damping(paper):
    """Zero damping: body energy gains exactly the spring energy stored at each touchdown.

    Stance conserves ``E = kinetic + zeta sin(psi) + alpha (1 - zeta)^2 / 2``, flight
    conserves ``kinetic + y``; chaining them over a jump checks both and the flip.
    """
    model = ModelParams(alpha=paper.alpha, d_hat=paper.d_hat)
    schedule = ControlSchedule.from_degrees([(30.0, 0.9), (34.0, 0.88)])
    orbit = iterate_map(model, schedule, (-0.9, -0.2), 8)
    assert orbit.failure is None
    for k in range(8):
        leg, next_leg = schedule[k], schedule[k + 1]
        before = 0.5 * np.sum(orbit.states[k] ** 2) + leg.zeta0 * math.sin(leg.psi0) + leg.stored_energy(model.alpha)
        height_after = orbit.rises[k] + next_leg.zeta0 * math.sin(next_leg.psi0)  # above this jump's foot
        after = 0.5 * np.sum(orbit.states[k + 1] ** 2) + height_after
        assert after == pytest.approx(before, rel=ENERGY_RTOL), f"energy over jump {k + 1}"


def test_mirror_symmetry_of_the_flip(paper, symmetric):
    """Mirroring the chute swaps the walls only: the flipped-frame map cannot tell."""
    start = np.array([-0.95, -0.1])
    direct = iterate_map(paper, symmetric, start, 4)
    # Starting one jump later is the same as starting on the right wall: same section sequence.
    later = iterate_map(paper, symmetric, direct.states[1], 3, first_jump=1)
    assert_allclose(later.states, direct.states[1:], rtol=0, atol=1e-15)


def test_batch_matches_single_runs(paper, alternating):
    rng = np.random.default_rng(1)
    starts = np.column_stack([rng.uniform(-1.2, -0.6, 50), rng.uniform(-0.6, 0.4, 50)])
    batch = iterate_map_batch(paper, alternating, starts, 5)
    for i in range(0, 50, 7):
        single = iterate_map(paper, alternating, starts[i], 5)
        count = single.jumps_completed
        assert batch.completed[i] == count
        assert_allclose(batch.states[i, : count + 1], single.states, rtol=0, atol=0)
        assert batch.failure(i) == single.failure


def test_batch_per_start_schedules(paper):
    schedules = np.array([ControlSchedule.from_degrees([(30.0, z)]).as_array() for z in (0.85, 0.9, 0.95)])
    batch = iterate_map_batch(paper, schedules, np.tile([-0.93, -0.17], (3, 1)), 4)
    for i, z in enumerate((0.85, 0.9, 0.95)):
        single = iterate_map(paper, ControlSchedule.from_degrees([(30.0, z)]), (-0.93, -0.17), 4)
        assert_allclose(batch.states[i], single.states, rtol=0, atol=0)


def test_batch_marks_bad_rows_instead_of_raising(paper, symmetric):
    batch = iterate_map_batch(paper, symmetric, [[-0.93, -0.17], [0.5, 0.0], [math.nan, 0.0]], 2)
    assert list(batch.status) == [OK, Failure.INVALID_STATE, Failure.INVALID_STATE]
    assert np.isnan(batch.states[1, 1:]).all()


@pytest.mark.parametrize(
    ("state", "field"),
    [((0.3, 0.0), "state.xdot"), ((math.nan, 0.0), "state.xdot"), ((-1.0, math.inf), "state.ydot")],
)
def test_bad_section_state_is_a_clear_error(paper, symmetric, state, field):
    with pytest.raises(ParameterError) as error:
        iterate_map(paper, symmetric, state, 3)
    assert error.value.field == field


def test_bad_jump_count(paper, symmetric):
    with pytest.raises(ParameterError, match="jumps"):
        iterate_map(paper, symmetric, (-0.9, 0.0), -1)
