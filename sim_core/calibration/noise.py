"""The noise in tracked touchdowns, estimated with the model: what calibration weighs its pairs by.

A pair's residual (predicted minus measured next touchdown) is not noise of one size. Its parts:

- the measured state of touchdown ``k`` is not the state the jump started from (the tracker's
  fit, the robot's own disturbance at touchdown): ``state_input`` [sqrt(g l0)] per component;
- each leg realises its controls with a per-jump error: ``psi0_deg`` [deg] and ``zeta0`` [l0];
- the next touchdown is measured with an error: ``state_output`` [sqrt(g l0)] and ``rise`` [l0].

The first two pass through the map, so a jump near failing — where the map is steep — carries
far more of them than a jump deep in a gait. Each pair's covariance is therefore
``S_q s_in^2 S_q^T + S_psi s_psi^2 S_psi^T + S_zeta s_zeta^2 S_zeta^T + diag(s_out^2, s_out^2, s_rise^2)``
with ``S`` the map's sensitivities (:func:`sim_core.calibration.touchdown_model.sensitivities`), and the five
sigmas are those that make the residuals most likely (Gaussian, per pair independent). They are
the noise a model of these runs should simulate (an MJTF study of the calibrated model).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np

# Columns of the sensitivities (sim_core.calibration.touchdown_model.INPUTS) each noise source enters by.
STATE_INPUTS, PSI0_INPUTS, ZETA0_INPUTS = [0, 1], [2, 4], [3, 5]
SIGMA_FLOOR = 1e-7


@dataclass(frozen=True)
class TouchdownNoise:
    """Sigmas of the noise in tracked touchdowns (module docstring); angles in degrees."""

    state_input: float = 0.01
    psi0_deg: float = 0.5
    zeta0: float = 0.003
    state_output: float = 0.005
    rise: float = 0.003

    def to_dict(self) -> dict:
        return asdict(self)

    def as_vector(self) -> np.ndarray:
        return np.array([self.state_input, math.radians(self.psi0_deg), self.zeta0, self.state_output, self.rise])

    @classmethod
    def of_vector(cls, vector) -> TouchdownNoise:
        s_in, s_psi, s_zeta, s_out, s_rise = (max(float(v), SIGMA_FLOOR) for v in vector)
        return cls(s_in, math.degrees(s_psi), s_zeta, s_out, s_rise)


def pair_covariances(sensitivity: np.ndarray, noise: TouchdownNoise) -> np.ndarray:
    """Shape (pairs, 3, 3): each pair's residual covariance under ``noise``."""
    s_in, s_psi, s_zeta, s_out, s_rise = noise.as_vector()
    covariance = np.zeros((sensitivity.shape[0], 3, 3))
    for columns, sigma in ((STATE_INPUTS, s_in), (PSI0_INPUTS, s_psi), (ZETA0_INPUTS, s_zeta)):
        part = sensitivity[:, :, columns]
        covariance += sigma**2 * part @ part.transpose(0, 2, 1)
    covariance += np.diag([s_out**2, s_out**2, s_rise**2])
    return covariance


def estimate_noise(residuals: np.ndarray, sensitivity: np.ndarray, start: TouchdownNoise) -> TouchdownNoise:
    """The sigmas that make ``residuals`` (pairs, 3) most likely; pairs with a failed prediction skipped."""
    from scipy.optimize import minimize

    usable = np.isfinite(residuals).all(axis=1) & np.isfinite(sensitivity).all(axis=(1, 2))
    r, sensitivity = residuals[usable], sensitivity[usable]

    def negative_log_likelihood(log_sigma: np.ndarray) -> float:
        covariance = pair_covariances(sensitivity, TouchdownNoise.of_vector(np.exp(log_sigma)))
        sign, log_det = np.linalg.slogdet(covariance)
        if np.any(sign <= 0):
            return math.inf
        mahalanobis = np.einsum("ij,ij->i", r, np.linalg.solve(covariance, r[:, :, None])[:, :, 0])
        return float(np.sum(log_det + mahalanobis))

    x0 = np.log(np.maximum(start.as_vector(), 1e-6))
    result = minimize(negative_log_likelihood, x0, method="Nelder-Mead",
                      options={"xatol": 1e-3, "fatol": 1e-3, "maxiter": 2000})  # fmt: skip
    return TouchdownNoise.of_vector(np.exp(result.x))


def whitening(covariance: np.ndarray) -> np.ndarray:
    """Shape (pairs, 3, 3): ``L^-1`` of each covariance's Cholesky factor, so ``L^-1 r`` has unit covariance."""
    factor = np.linalg.cholesky(covariance)
    return np.linalg.inv(factor)
