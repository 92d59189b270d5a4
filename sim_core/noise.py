"""Noisy jumps: the disturbance model behind MJTF, the closed-loop runs and the virtual robot (docs/model.md §5).

Per jump, Gaussian noise on the leg angle ``psi0``, the leg length ``zeta0`` and each
component of the section state; a constant L/R asymmetry (the right leg's controls offset,
as the paper observed on the robot); and a body pitch that drifts as a random walk and
offsets both leg angles — the paper's main failure mode.

Pitch sign: a body rotated counter-clockwise by ``theta`` turns the leg on the left wall to
``psi0 + theta`` and the leg on the right wall to ``psi0 - theta`` (in the flipped section
frame both are measured from the wall normal, upward). Jump ``k`` (0-based) stands on
:func:`sim_core.walls.wall_of` ``(k)`` (the left wall for even ``k``) and uses the schedule's row
``k mod m``; right-wall jumps carry the asymmetry offsets.

Clamps: noise never takes a leg outside the model's control domain (``LegControl``: ``psi0`` in
(0, 90°), ``zeta0`` in (0, 1)). The noisy controls are clamped to :data:`PSI0_LIMITS` and
:data:`ZETA0_LIMITS`, just inside it: a leg cannot touch down longer than its rest length, and a
draw that would put it there is a saturated actuator, not a failure of the jump. (Before, the
kernels did not clamp: a draw past ``zeta0 = 1`` ended an MJTF trial as ``invalid_state``.)

Each rule is written once, as a compiled function of the draws (:func:`noisy_controls`,
:func:`drifted_pitch`, :func:`disturbed`). Two samplers feed them: the kernels here
(:func:`perturbed_controls`, :func:`pitch_step`, :func:`disturbed_state`; numba's generator,
seeded once per trial, so MJTF and the PID study depend only on their seed, never on the number
of threads or workers), and :class:`NoiseSampler` (a numpy ``Generator``), which the climb
sequencer (:mod:`sim_core.climb`) uses for the virtual robot. Both draw in the same order: a
pitch step, then ``psi0``, then ``zeta0`` of the next leg; after the jump, ``xdot`` then ``ydot``;
a zero standard deviation draws nothing.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np

from sim_core._jit import kernel
from sim_core.controls import PSI0_COLUMN, ZETA0_COLUMN, LegControl
from sim_core.validation import check_range
from sim_core.walls import Wall

CONTROL_MARGIN = 1e-6  # how far inside the control domain the clamps sit [rad, l0]
PSI0_LIMITS = (CONTROL_MARGIN, 0.5 * math.pi - CONTROL_MARGIN)  # [rad]
ZETA0_LIMITS = (CONTROL_MARGIN, 1.0 - CONTROL_MARGIN)  # [l0]
PSI0_MIN, PSI0_MAX = PSI0_LIMITS
ZETA0_MIN, ZETA0_MAX = ZETA0_LIMITS


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


# The rules, as functions of the draws ------------------------------------------------------------
@kernel
def noisy_controls(psi0, zeta0, right_leg, pitch, asymmetry_psi0, asymmetry_zeta0, psi0_draw, zeta0_draw):
    """A leg's controls as the robot realises them: ``(psi0, zeta0)`` [rad, l0].

    The pitch turns the left wall's leg by ``+pitch`` and the right wall's by ``-pitch``; the
    right leg carries the asymmetry offsets; the draws (zero-mean noise) are added last and the
    result is clamped to :data:`PSI0_LIMITS`, :data:`ZETA0_LIMITS`.
    """
    psi0 = psi0 + (-pitch if right_leg else pitch)
    if right_leg:
        psi0 += asymmetry_psi0
        zeta0 += asymmetry_zeta0
    psi0 += psi0_draw
    zeta0 += zeta0_draw
    return min(max(psi0, PSI0_MIN), PSI0_MAX), min(max(zeta0, ZETA0_MIN), ZETA0_MAX)


@kernel
def drifted_pitch(pitch, draw):
    """The pitch random walk's step: the next jump's pitch [rad]."""
    return pitch + draw


@kernel
def disturbed(xdot, ydot, xdot_draw, ydot_draw):
    """The section state after a jump with process noise on each component."""
    return xdot + xdot_draw, ydot + ydot_draw


# The compiled sampler (numba's generator) -------------------------------------------------------
@kernel
def _draw(sigma):
    return np.random.normal(0.0, sigma) if sigma > 0.0 else 0.0


@kernel
def perturbed_controls(schedule, k, pitch, base_zeta0, sigma_psi0, sigma_zeta0, asymmetry_psi0, asymmetry_zeta0):
    """Controls ``(psi0, zeta0)`` of jump ``k`` with pitch ``pitch`` and fresh noise.

    ``base_zeta0`` replaces the schedule's zeta0 when finite (the closed loop's command).
    """
    row = k % schedule.shape[0]
    zeta0 = schedule[row, ZETA0_COLUMN] if math.isnan(base_zeta0) else base_zeta0
    right_leg = k % 2 == 1  # sim_core.walls.wall_of(k) is Wall.RIGHT, spelled for numba
    psi0_draw = _draw(sigma_psi0)
    zeta0_draw = _draw(sigma_zeta0)
    return noisy_controls(
        schedule[row, PSI0_COLUMN], zeta0, right_leg, pitch, asymmetry_psi0, asymmetry_zeta0, psi0_draw, zeta0_draw
    )


@kernel
def disturbed_state(xdot, ydot, sigma_velocity):
    """The section state with measurement-free process noise added to each component."""
    xdot_draw = _draw(sigma_velocity)
    ydot_draw = _draw(sigma_velocity)
    return disturbed(xdot, ydot, xdot_draw, ydot_draw)


@kernel
def pitch_step(pitch, sigma_pitch):
    return drifted_pitch(pitch, _draw(sigma_pitch))


# The Python sampler (a numpy Generator) ----------------------------------------------------------
class NoiseSampler:
    """The same rules drawn from a numpy ``Generator``, one leg at a time (the climb sequencer's).

    Args:
        noise: the disturbances; rng: the generator (seed it for a reproducible climb).
    """

    def __init__(self, noise: NoiseModel, rng: np.random.Generator):
        self.noise, self.rng = noise, rng
        (self._psi0, self._zeta0, self._velocity, self._pitch, self._asymmetry_psi0, self._asymmetry_zeta0) = (
            noise.kernel_args()
        )

    def _draw(self, sigma: float) -> float:
        return float(self.rng.normal(0.0, sigma)) if sigma > 0.0 else 0.0

    def pitch_step(self, pitch: float) -> float:
        """The next jump's pitch [rad]."""
        return float(drifted_pitch(pitch, self._draw(self._pitch)))

    def controls(self, commanded: LegControl, wall: Wall, pitch: float) -> LegControl:
        """The controls the leg on ``wall`` touches down with, commanded ``commanded``, at ``pitch`` [rad]."""
        psi0_draw = self._draw(self._psi0)
        zeta0_draw = self._draw(self._zeta0)
        psi0, zeta0 = noisy_controls(
            commanded.psi0,
            commanded.zeta0,
            wall == Wall.RIGHT,
            pitch,
            self._asymmetry_psi0,
            self._asymmetry_zeta0,
            psi0_draw,
            zeta0_draw,
        )
        return LegControl(float(psi0), float(zeta0))

    def state(self, state) -> tuple[float, float]:
        """A section state ``(xdot, ydot)`` after a jump, with process noise."""
        xdot_draw = self._draw(self._velocity)
        ydot_draw = self._draw(self._velocity)
        xdot, ydot = disturbed(float(state[0]), float(state[1]), xdot_draw, ydot_draw)
        return float(xdot), float(ydot)
