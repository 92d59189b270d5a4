"""The noise in tracked touchdowns (sim_core.calibration.noise): each source's covariance through the
map's sensitivities, the whitening, and sigmas recovered from residuals drawn with known ones."""

import math

import numpy as np
import pytest
from numpy.testing import assert_allclose

from sim_core.calibration.noise import (
    PSI0_INPUTS,
    SIGMA_FLOOR,
    STATE_INPUTS,
    ZETA0_INPUTS,
    TouchdownNoise,
    estimate_noise,
    pair_covariances,
    whitening,
)

# Sources of comparable size at unit sensitivities, so each can be told apart from the others.
TRUE = TouchdownNoise(state_input=0.01, psi0_deg=0.6, zeta0=0.008, state_output=0.012, rise=0.01)
RECOVERY_RTOL = 0.15  # 4000 pairs: a sigma's estimate scatters by a few percent


def _sensitivities(pairs: int, seed: int = 0) -> np.ndarray:
    """Shape (pairs, 3, 6): made-up map sensitivities of the size a gait has (order 1)."""
    return np.random.default_rng(seed).normal(0.0, 1.0, (pairs, 3, 6))


def test_the_vector_is_in_radians_and_back_in_degrees():
    vector = TRUE.as_vector()
    assert vector[1] == pytest.approx(math.radians(0.6))
    assert TouchdownNoise.of_vector(vector) == pytest.approx(TRUE)
    assert list(TRUE.to_dict()) == ["state_input", "psi0_deg", "zeta0", "state_output", "rise"]


def test_sigmas_are_floored_above_zero():
    floored = TouchdownNoise.of_vector([0.0, -1.0, 1e-12, 0.01, 0.0])
    assert floored.state_input == floored.zeta0 == floored.rise == SIGMA_FLOOR
    assert floored.psi0_deg == pytest.approx(math.degrees(SIGMA_FLOOR))


def test_the_sources_enter_by_their_own_columns():
    assert sorted(STATE_INPUTS + PSI0_INPUTS + ZETA0_INPUTS) == list(range(6))


def test_without_sensitivity_only_the_measurement_noise_is_left():
    covariance = pair_covariances(np.zeros((2, 3, 6)), TRUE)
    assert_allclose(covariance, np.broadcast_to(np.diag([0.012**2, 0.012**2, 0.01**2]), (2, 3, 3)))


def test_each_source_passes_through_its_sensitivity():
    sensitivity = np.zeros((1, 3, 6))
    sensitivity[0, :, PSI0_INPUTS[0]] = [1.0, 2.0, 0.0]  # the stance leg's angle moves xdot and ydot
    quiet = TouchdownNoise(state_input=0.0, psi0_deg=1.0, zeta0=0.0, state_output=0.0, rise=0.0)
    covariance = pair_covariances(sensitivity, quiet)[0]
    sigma = math.radians(1.0)
    assert_allclose(covariance, sigma**2 * np.outer([1.0, 2.0, 0.0], [1.0, 2.0, 0.0]), rtol=1e-12)


def test_whitening_gives_unit_covariance():
    covariance = pair_covariances(_sensitivities(5), TRUE)
    assert_allclose(covariance, covariance.transpose(0, 2, 1), rtol=1e-14, err_msg="symmetric")
    inverse_factor = whitening(covariance)
    white = inverse_factor @ covariance @ inverse_factor.transpose(0, 2, 1)
    assert_allclose(white, np.broadcast_to(np.eye(3), white.shape), atol=1e-9)


def _residuals(sensitivity: np.ndarray, noise: TouchdownNoise, seed: int = 1) -> np.ndarray:
    """Residuals drawn source by source as the module docstring composes them."""
    rng = np.random.default_rng(seed)
    s_in, s_psi, s_zeta, s_out, s_rise = noise.as_vector()
    pairs = sensitivity.shape[0]
    inputs = np.zeros((pairs, 6))
    inputs[:, STATE_INPUTS] = rng.normal(0.0, s_in, (pairs, 2))
    inputs[:, PSI0_INPUTS] = rng.normal(0.0, s_psi, (pairs, 2))
    inputs[:, ZETA0_INPUTS] = rng.normal(0.0, s_zeta, (pairs, 2))
    outputs = rng.normal(0.0, 1.0, (pairs, 3)) * [s_out, s_out, s_rise]
    return np.einsum("pij,pj->pi", sensitivity, inputs) + outputs


def test_the_most_likely_sigmas_are_the_ones_drawn_with():
    sensitivity = _sensitivities(4000)
    residuals = _residuals(sensitivity, TRUE)
    residuals[:10] = np.nan  # failed predictions are skipped, not fitted
    found = estimate_noise(residuals, sensitivity, TouchdownNoise())
    assert_allclose(found.as_vector(), TRUE.as_vector(), rtol=RECOVERY_RTOL)
