"""Noisy jumps: the disturbance model behind MJTF, the closed-loop runs and the virtual robot (docs/model.md §5).

Per jump, Gaussian noise on the leg angle ``psi0``, the leg length ``zeta0`` and each
component of the section state; a constant L/R asymmetry (the right leg's controls offset,
as the paper observed on the robot); and a body pitch that drifts as a random walk and
offsets both leg angles — the paper's main failure mode.

This module is the model's parameters (:class:`NoiseModel`: their defaults, and their ranges in
:data:`SIGMA_LIMITS` and :data:`ASYMMETRY_LIMITS`), the clamps and the trial seeds: numpy only, so
options, request schemas and stored job specs read its defaults and ranges without loading the
kernels. How
the noise is drawn — each rule once, compiled, and the two samplers that feed it — is
:mod:`sim_core.model.noise_rules`.

Pitch sign: a body rotated counter-clockwise by ``theta`` turns the leg on the left wall to
``psi0 + theta`` and the leg on the right wall to ``psi0 - theta`` (in the flipped section
frame both are measured from the wall normal, upward). Jump ``k`` (0-based) stands on
:func:`sim_core.model.walls.wall_of` ``(k)`` (the left wall for even ``k``) and uses the schedule's row
``k mod m``; right-wall jumps carry the asymmetry offsets.

Clamps: noise never takes a leg outside the model's control domain (``LegControl``: ``psi0`` in
(0, 90°), ``zeta0`` in (0, 1)). The noisy controls are clamped to :data:`PSI0_LIMITS` and
:data:`ZETA0_LIMITS`, just inside it: a leg cannot touch down longer than its rest length, and a
draw that would put it there is a saturated actuator, not a failure of the jump. (Before, the
kernels did not clamp: a draw past ``zeta0 = 1`` ended an MJTF trial as ``invalid_state``.)
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import NamedTuple

import numpy as np

from sim_core.model.validation import check_range

CONTROL_MARGIN = 1e-6  # how far inside the control domain the clamps sit [rad, l0]
PSI0_LIMITS = (CONTROL_MARGIN, 0.5 * math.pi - CONTROL_MARGIN)  # [rad]
ZETA0_LIMITS = (CONTROL_MARGIN, 1.0 - CONTROL_MARGIN)  # [l0]
PSI0_MIN, PSI0_MAX = PSI0_LIMITS
ZETA0_MIN, ZETA0_MAX = ZETA0_LIMITS
# The noise's ranges, by NoiseModel field: each standard deviation in [0, limit), each asymmetry
# offset in (-limit, limit). The API's request schema states the same ranges from these.
SIGMA_LIMITS = {"psi0_deg": 30.0, "zeta0": 0.2, "velocity": 1.0, "pitch_drift_deg": 30.0}
ASYMMETRY_LIMITS = {"asymmetry_psi0_deg": 30.0, "asymmetry_zeta0": 0.5}


class NoiseRecord(NamedTuple):
    """:class:`NoiseModel` as the compiled kernels take it (:meth:`NoiseModel.record`): one typed
    argument, read by field (``noise.sigma_pitch``), angles in radians. numba types it as a named
    tuple of six float64."""

    sigma_psi0: float  # standard deviation of the leg angle at touchdown [rad]
    sigma_zeta0: float  # standard deviation of the leg length at touchdown [l0]
    sigma_velocity: float  # standard deviation of each section-state component [sqrt(g l0)]
    sigma_pitch: float  # standard deviation of the pitch random walk's step [rad]
    asymmetry_psi0: float  # the right leg's leg-angle offset [rad]
    asymmetry_zeta0: float  # the right leg's leg-length offset [l0]


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
        for field, limit in SIGMA_LIMITS.items():
            check_range(f"noise.{field}", getattr(self, field), 0.0, limit, low_open=False)  # sigmas: [0, limit)
        for field, limit in ASYMMETRY_LIMITS.items():
            check_range(f"noise.{field}", getattr(self, field), -limit, limit)

    def record(self) -> NoiseRecord:
        """The noise as the compiled kernels take it, angles in radians, every value a float."""
        return NoiseRecord(
            sigma_psi0=math.radians(self.psi0_deg),
            sigma_zeta0=float(self.zeta0),
            sigma_velocity=float(self.velocity),
            sigma_pitch=math.radians(self.pitch_drift_deg),
            asymmetry_psi0=math.radians(self.asymmetry_psi0_deg),
            asymmetry_zeta0=float(self.asymmetry_zeta0),
        )

    def to_dict(self) -> dict:
        return asdict(self)


NO_NOISE = NoiseModel(0.0, 0.0, 0.0, 0.0)


def trial_seeds(seed: int, stream: int, trials: int) -> np.ndarray:
    """Independent 32-bit seeds for ``trials`` trials of one stream (e.g. one energy level)."""
    check_range("seed", seed, 0, 2**63, low_open=False)
    check_range("stream", stream, 0, 2**63, low_open=False)
    return np.random.SeedSequence([int(seed), int(stream)]).generate_state(trials).astype(np.int64)
