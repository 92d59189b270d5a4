"""Noisy jumps: the disturbance model behind MJTF and the closed-loop runs (model.md §5).

Per jump, Gaussian noise on the leg angle ``psi0``, the leg length ``zeta0`` and each
component of the section state; a constant L/R asymmetry (the right leg's controls offset,
as the paper observed on the robot); and a body pitch that drifts as a random walk and
offsets both leg angles — the paper's main failure mode.

Pitch sign: a body rotated counter-clockwise by ``theta`` turns the leg on the left wall to
``psi0 + theta`` and the leg on the right wall to ``psi0 - theta`` (in the flipped section
frame both are measured from the wall normal, upward). Jump ``k`` (0-based) stands on the
left wall for even ``k``; it uses the schedule's row ``k mod m``; odd ``k`` are right-leg
jumps, which carry the asymmetry offsets.

Randomness lives in compiled kernels (numba's generator, seeded once per trial), so a run
depends only on its seed, never on the number of threads or workers executing it.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np

from sim_core._jit import kernel
from sim_core.controls import PSI0_COLUMN, ZETA0_COLUMN
from sim_core.validation import check_range


@dataclass(frozen=True)
class NoiseModel:
    """Disturbances per jump; angles in degrees, lengths in l0, velocities in sqrt(g l0).

    Attributes:
        psi0_deg: standard deviation of the leg angle at touchdown.
        zeta0: standard deviation of the leg length at touchdown.
        velocity: standard deviation of each section-state component after a jump.
        pitch_drift_deg: standard deviation of the pitch random walk's step per jump.
        asymmetry_psi0_deg, asymmetry_zeta0: constant offset of the right leg's controls.
    """

    psi0_deg: float = 0.5
    zeta0: float = 0.003
    velocity: float = 0.01
    pitch_drift_deg: float = 0.5
    asymmetry_psi0_deg: float = 0.0
    asymmetry_zeta0: float = 0.0

    def __post_init__(self) -> None:
        check_range("noise.psi0_deg", self.psi0_deg, 0.0, 30.0, low_open=False)
        check_range("noise.zeta0", self.zeta0, 0.0, 0.2, low_open=False)
        check_range("noise.velocity", self.velocity, 0.0, 1.0, low_open=False)
        check_range("noise.pitch_drift_deg", self.pitch_drift_deg, 0.0, 30.0, low_open=False)
        check_range("noise.asymmetry_psi0_deg", self.asymmetry_psi0_deg, -30.0, 30.0)
        check_range("noise.asymmetry_zeta0", self.asymmetry_zeta0, -0.5, 0.5)

    def kernel_args(self) -> tuple[float, ...]:
        """``(sigma_psi0, sigma_zeta0, sigma_velocity, sigma_pitch, asymmetry_psi0, asymmetry_zeta0)``, radians."""
        return (
            math.radians(self.psi0_deg),
            self.zeta0,
            self.velocity,
            math.radians(self.pitch_drift_deg),
            math.radians(self.asymmetry_psi0_deg),
            self.asymmetry_zeta0,
        )

    def to_dict(self) -> dict:
        return asdict(self)


NO_NOISE = NoiseModel(0.0, 0.0, 0.0, 0.0)


def trial_seeds(seed: int, stream: int, trials: int) -> np.ndarray:
    """Independent 32-bit seeds for ``trials`` trials of one stream (e.g. one energy level)."""
    check_range("seed", seed, 0, 2**63, low_open=False)
    check_range("stream", stream, 0, 2**63, low_open=False)
    return np.random.SeedSequence([int(seed), int(stream)]).generate_state(trials).astype(np.int64)


@kernel
def seed_trial(seed):
    """Seed numba's generator (per thread) at the start of a trial."""
    np.random.seed(seed)


@kernel
def perturbed_controls(schedule, k, pitch, base_zeta0, sigma_psi0, sigma_zeta0, asymmetry_psi0, asymmetry_zeta0):
    """Controls ``(psi0, zeta0)`` of jump ``k`` with pitch ``pitch`` and fresh noise.

    ``base_zeta0`` replaces the schedule's zeta0 when finite (the closed loop's command).
    """
    row = k % schedule.shape[0]
    right_leg = k % 2 == 1
    psi0 = schedule[row, PSI0_COLUMN] + (-pitch if right_leg else pitch)
    zeta0 = schedule[row, ZETA0_COLUMN] if math.isnan(base_zeta0) else base_zeta0
    if right_leg:
        psi0 += asymmetry_psi0
        zeta0 += asymmetry_zeta0
    if sigma_psi0 > 0.0:
        psi0 += np.random.normal(0.0, sigma_psi0)
    if sigma_zeta0 > 0.0:
        zeta0 += np.random.normal(0.0, sigma_zeta0)
    return psi0, zeta0


@kernel
def disturbed_state(xdot, ydot, sigma_velocity):
    """The section state with measurement-free process noise added to each component."""
    if sigma_velocity > 0.0:
        xdot += np.random.normal(0.0, sigma_velocity)
        ydot += np.random.normal(0.0, sigma_velocity)
    return xdot, ydot


@kernel
def pitch_step(pitch, sigma_pitch):
    return pitch + np.random.normal(0.0, sigma_pitch) if sigma_pitch > 0.0 else pitch
