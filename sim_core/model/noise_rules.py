"""How the noise of :mod:`sim_core.model.noise` is drawn: each rule once, compiled, and two samplers.

Each rule is written once, as a compiled function of the draws (:func:`noisy_controls`,
:func:`drifted_pitch`, :func:`disturbed`; docs/model.md §5.1). Two samplers feed them: the kernels
here (:func:`perturbed_controls`, :func:`pitch_step`, :func:`disturbed_state`; numba's generator,
seeded once per trial, so MJTF and the PID study depend only on their seed, never on the number
of threads or workers; each takes the noise as one record, :meth:`sim_core.model.noise.NoiseModel.record`),
and :class:`NoiseSampler` (a numpy ``Generator``), which the climb sequencer
(:mod:`sim_core.climb.sequencer`) uses for the virtual robot. Both draw in the same order: a
pitch step, then ``psi0``, then ``zeta0`` of the next leg; after the jump, ``xdot`` then ``ydot``;
a zero standard deviation draws nothing. The ``tallied_`` kernels draw exactly as theirs and also
count what they drew (a followed plan's trials, which importance sampling weighs by their draws).
"""

from __future__ import annotations

import math

import numpy as np

from sim_core._jit import kernel
from sim_core.model.controls import PSI0_COLUMN, ZETA0_COLUMN, LegControl
from sim_core.model.noise import PSI0_MAX, PSI0_MIN, ZETA0_MAX, ZETA0_MIN, NoiseModel
from sim_core.model.walls import Wall


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
    result is clamped to :data:`sim_core.model.noise.PSI0_LIMITS` and :data:`~sim_core.model.noise.ZETA0_LIMITS`.
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
def perturbed_controls(schedule, k, pitch, base_zeta0, noise):
    """Controls ``(psi0, zeta0)`` of jump ``k`` with pitch ``pitch`` and fresh noise (``noise``: a
    :class:`sim_core.model.noise.NoiseRecord`).

    ``base_zeta0`` replaces the schedule's zeta0 when finite (the closed loop's command).
    """
    row = k % schedule.shape[0]
    zeta0 = schedule[row, ZETA0_COLUMN] if math.isnan(base_zeta0) else base_zeta0
    return commanded_controls(k, pitch, schedule[row, PSI0_COLUMN], zeta0, noise)


@kernel
def commanded_controls(k, pitch, psi0, zeta0, noise):
    """Controls ``(psi0, zeta0)`` of jump ``k`` commanded ``(psi0, zeta0)``, with pitch ``pitch``
    and fresh noise (the draws in the order :func:`perturbed_controls` takes them)."""
    right_leg = k % 2 == 1  # sim_core.model.walls.wall_of(k) is Wall.RIGHT, spelled for numba
    psi0_draw = _draw(noise.sigma_psi0)
    zeta0_draw = _draw(noise.sigma_zeta0)
    return noisy_controls(
        psi0, zeta0, right_leg, pitch, noise.asymmetry_psi0, noise.asymmetry_zeta0, psi0_draw, zeta0_draw
    )


@kernel
def disturbed_state(xdot, ydot, noise):
    """The section state with measurement-free process noise added to each component."""
    xdot_draw = _draw(noise.sigma_velocity)
    ydot_draw = _draw(noise.sigma_velocity)
    return disturbed(xdot, ydot, xdot_draw, ydot_draw)


@kernel
def pitch_step(pitch, noise):
    """The next jump's pitch [rad], drawn."""
    return drifted_pitch(pitch, _draw(noise.sigma_pitch))


# The compiled sampler, tallying its draws (importance sampling) ----------------------------------
# The same generator calls as the kernels above, in the same order, so a trial draws exactly what
# they draw; each draw is also added to ``tally`` (TALLY_SIZE floats: per kind of draw, in
# NoiseRecord's order of the sigmas, the draws made and the sum of their squares in units of their
# standard deviation, i.e. of the standard normals drawn). An importance-sampled trial draws from a
# proposal (sigmas scaled) and is weighed by its draws' likelihood ratio, which needs only that
# tally (sim_core.planning.plan_importance). MJTF and the PID study keep the kernels above.
TALLY_PSI0, TALLY_ZETA0, TALLY_VELOCITY, TALLY_PITCH = range(4)  # NoiseRecord's sigma_* in order
TALLY_KINDS = ("psi0", "zeta0", "velocity", "pitch")
TALLY_SIZE = 2 * len(TALLY_KINDS)  # [2 kind]: the draws of that kind, [2 kind + 1]: their squares


@kernel
def tallied_draw(sigma, tally, kind):
    """:func:`_draw`'s draw, counted in ``tally[2 kind]`` and its square in units of ``sigma`` added to
    ``tally[2 kind + 1]``."""
    if sigma <= 0.0:
        return 0.0  # nothing drawn, nothing tallied: a zero sigma is no random variable
    draw = np.random.normal(0.0, sigma)
    standard = draw / sigma
    tally[2 * kind] += 1.0
    tally[2 * kind + 1] += standard * standard
    return draw


@kernel
def tallied_commanded_controls(k, pitch, psi0, zeta0, noise, tally):
    """:func:`commanded_controls`, its draws tallied in ``tally``."""
    right_leg = k % 2 == 1
    psi0_draw = tallied_draw(noise.sigma_psi0, tally, TALLY_PSI0)
    zeta0_draw = tallied_draw(noise.sigma_zeta0, tally, TALLY_ZETA0)
    return noisy_controls(
        psi0, zeta0, right_leg, pitch, noise.asymmetry_psi0, noise.asymmetry_zeta0, psi0_draw, zeta0_draw
    )


@kernel
def tallied_disturbed_state(xdot, ydot, noise, tally):
    """:func:`disturbed_state`, its draws tallied in ``tally``."""
    xdot_draw = tallied_draw(noise.sigma_velocity, tally, TALLY_VELOCITY)
    ydot_draw = tallied_draw(noise.sigma_velocity, tally, TALLY_VELOCITY)
    return disturbed(xdot, ydot, xdot_draw, ydot_draw)


@kernel
def tallied_pitch_step(pitch, noise, tally):
    """:func:`pitch_step`, its draw tallied in ``tally``."""
    return drifted_pitch(pitch, tallied_draw(noise.sigma_pitch, tally, TALLY_PITCH))


# The Python sampler (a numpy Generator) ----------------------------------------------------------
class NoiseSampler:
    """The same rules drawn from a numpy ``Generator``, one leg at a time (the climb sequencer's).

    Args:
        noise: the disturbances; rng: the generator (seed it for a reproducible climb).
    """

    def __init__(self, noise: NoiseModel, rng: np.random.Generator):
        self.noise, self.rng = noise, rng
        self._record = noise.record()

    def _draw(self, sigma: float) -> float:
        return float(self.rng.normal(0.0, sigma)) if sigma > 0.0 else 0.0

    def pitch_step(self, pitch: float) -> float:
        """The next jump's pitch [rad]."""
        return float(drifted_pitch(pitch, self._draw(self._record.sigma_pitch)))

    def controls(self, commanded: LegControl, wall: Wall, pitch: float) -> LegControl:
        """The controls the leg on ``wall`` touches down with, commanded ``commanded``, at ``pitch`` [rad]."""
        noise = self._record
        psi0_draw = self._draw(noise.sigma_psi0)
        zeta0_draw = self._draw(noise.sigma_zeta0)
        psi0, zeta0 = noisy_controls(
            commanded.psi0,
            commanded.zeta0,
            wall == Wall.RIGHT,
            pitch,
            noise.asymmetry_psi0,
            noise.asymmetry_zeta0,
            psi0_draw,
            zeta0_draw,
        )
        return LegControl(float(psi0), float(zeta0))

    def state(self, state) -> tuple[float, float]:
        """A section state ``(xdot, ydot)`` after a jump, with process noise."""
        xdot_draw = self._draw(self._record.sigma_velocity)
        ydot_draw = self._draw(self._record.sigma_velocity)
        xdot, ydot = disturbed(float(state[0]), float(state[1]), xdot_draw, ydot_draw)
        return float(xdot), float(ydot)
