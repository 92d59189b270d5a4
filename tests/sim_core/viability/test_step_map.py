"""sim_core/viability/step_map.py: the ParkourBot's mid-chute step map keeps its gaits' flights
fixed, carries the pitch over to the other wall, and its grid refuses what it cannot take."""

import math

import numpy as np
import pytest

from sim_core import ControlSchedule, find_fixed_point
from sim_core.model.params import ModelParams
from sim_core.model.validation import ParameterError
from sim_core.viability.engine import compute_viability
from sim_core.viability.grid import section_grid
from sim_core.viability.step_map import section_step_map


def middle_of(model, touchdown, psi0, zeta0):
    """The flight's mid-chute velocity that ends in ``touchdown`` (the section state after the flip)
    with the leg at ``(psi0, zeta0)``: the flight's xdot is constant and gravity is -1."""
    xdot = -touchdown[0]
    return np.array([xdot, touchdown[1] + (0.5 * model.d_hat - zeta0 * math.cos(psi0)) / xdot])


@pytest.mark.parametrize(("psi0_deg", "zeta0"), [(30.0, 0.9), (33.0, 0.87), (27.0, 0.93)])
def test_a_gaits_flight_is_a_fixed_point_and_in_the_kernel(paper, psi0_deg, zeta0):
    gait = find_fixed_point(paper, ControlSchedule.from_degrees([(psi0_deg, zeta0)]), 1, (-0.93, -0.2))
    psi0 = math.radians(psi0_deg)
    middle = middle_of(paper, gait.state, psi0, zeta0)
    reached, failed = section_step_map(paper)(middle[None, :], np.array([[psi0, zeta0]]))
    assert not failed[0]
    np.testing.assert_allclose(reached[0], middle, atol=1e-9)
    grid = section_grid(states=20, actions=8)
    result = compute_viability(section_step_map(paper), grid)
    assert result.kernel[result.nearest_node(middle)]
    assert 0.0 < result.kernel_fraction < 1.0, "the default window shows the kernel's edge"


def test_a_calibrated_models_kernel_is_its_own(paper):
    """The step map of a model a calibration fitted (here: a stiffer spring, less damping, a
    narrower chute, as `parkour calibrate` might return) is that model's: its gait's flight is a
    fixed point inside its kernel, and the kernel is not the paper's."""
    calibrated = ModelParams(alpha=1.08 * paper.alpha, d_hat=2.3, c_zeta=0.22, c_psi=0.25, mu=1.6)
    gait = find_fixed_point(calibrated, ControlSchedule.from_degrees([(30.0, 0.9)]), 1, (-0.93, -0.2))
    psi0 = math.radians(30.0)
    middle = middle_of(calibrated, gait.state, psi0, 0.9)
    reached, failed = section_step_map(calibrated)(middle[None, :], np.array([[psi0, 0.9]]))
    assert not failed[0]
    np.testing.assert_allclose(reached[0], middle, atol=1e-9)
    grid = section_grid(states=20, actions=8)
    own, papers = (compute_viability(section_step_map(model), grid) for model in (calibrated, paper))
    assert own.kernel[own.nearest_node(middle)]
    assert 0.0 < own.kernel_fraction < 1.0 and not np.array_equal(own.kernel, papers.kernel)


def test_the_pitch_turns_the_coming_leg_and_changes_sign_for_the_next(paper):
    pitch = math.radians(2.0)
    state = np.array([[1.0, 0.5, pitch]])
    action = np.array([[math.radians(30.0), 0.9]])
    reached, failed = section_step_map(paper, with_pitch=True)(state, action)
    turned, _ = section_step_map(paper)(state[:, :2], action + np.array([[pitch, 0.0]]))
    assert not failed[0]
    np.testing.assert_allclose(reached[0, :2], turned[0], atol=1e-12)
    assert reached[0, 2] == -pitch


def test_a_step_that_cannot_go_on_fails(paper):
    # Rising fast onto a steep, long leg: the stance does not end in a flight across.
    _, failed = section_step_map(paper)(np.array([[0.94, 0.9]]), np.array([[math.radians(55.0), 0.98]]))
    assert failed[0]


def test_a_chute_too_narrow_for_a_middle_is_refused():
    with pytest.raises(ParameterError, match="d_hat: must exceed 2"):
        section_step_map(ModelParams(alpha=77.6, d_hat=1.9, c_zeta=0.3, c_psi=0.3, mu=2.0))
