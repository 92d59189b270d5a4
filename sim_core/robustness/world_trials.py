"""MJTF's trials in a world (docs/model.md §8), compiled: the noisy climb of
:mod:`sim_core.robustness.mjtf_trials` with the world's stride, from touchdown 0 on the left side.

The noise is drawn in the same order as there (:mod:`sim_core.model.noise_rules`: at each lift-off
a pitch step and the next leg's controls, after each jump the velocity) from the trial's own seed.
The velocity noise disturbs the body's ``(xdot, ydot)`` at touchdown in the side's stance frame,
as the map's section state is disturbed. A world has heights, so a trial also ends at the chute's
floor (docs/model.md §7.2): a touchdown with the body below ``y = 0`` fails with ``floor``.
"""

from __future__ import annotations

import math

import numpy as np
from numba import prange

from sim_core._jit import kernel, parallel_kernel
from sim_core.model.failures import FLOOR, FLOOR_HEIGHT, OK
from sim_core.model.integrate import STATE_SIZE
from sim_core.model.noise import NoiseModel
from sim_core.model.noise_rules import (
    disturbed_state,
    perturbed_controls,
    pitch_step,
    seed_trial,
    tallied_disturbed_state,
)
from sim_core.model.params import ModelParams
from sim_core.model.poincare import check_section_state
from sim_core.model.validation import check_range
from sim_core.world.climb import start_foot
from sim_core.world.geometry import pack
from sim_core.world.stride import world_jump
from sim_core.world.world import World

REACHED = -1  # a trial's status when its foot reached the goal (beside OK at the cap and the failures)


def run_world_trials(
    model: ModelParams,
    schedule: np.ndarray,
    start,
    noise: NoiseModel,
    seeds: np.ndarray,
    cap: int,
    world: World,
    foot_y: float,
    goal: float = math.inf,
) -> tuple[np.ndarray, np.ndarray]:
    """One trial per seed in ``world`` on all cores, touchdown 0 with velocity ``start`` and the
    foot at ``foot_y`` [l0] under schedule row 0: ``(jumps completed, status)`` arrays; a trial
    whose foot reaches ``goal`` [l0] ends there with status :data:`REACHED`."""
    velocity = check_section_state(start)
    foot_y = check_range("foot_y", foot_y)
    sides = pack(world, model.mu)
    foot_x, segment = start_foot(sides, foot_y)
    jumps = np.empty(seeds.size, dtype=np.int64)
    status = np.empty(seeds.size, dtype=np.int64)
    world_trials_batch(np.array([foot_x, foot_y]), velocity, segment, schedule, seeds, cap, float(goal),
                       noise.record(), model.record(), sides, jumps, status)  # fmt: skip
    return jumps, status


@kernel
def world_trial(foot, velocity, segment, schedule, seed, cap, goal, noise, model, sides):
    """One noisy climb from the foot of touchdown 0 (on the left side, ``segment``) and the body's
    ``velocity`` there: ``(jumps completed, status of the failing jump, OK at the cap or REACHED
    at a foot at ``goal`` [l0] or higher)``."""
    seed_trial(seed)
    no_record = np.empty((0, STATE_SIZE))
    side = 0
    pitch = 0.0
    psi0, zeta0 = perturbed_controls(schedule, 0, pitch, math.nan, noise)
    # the leg as realised sets where the body is at touchdown 0
    x, y = foot[0] + zeta0 * math.cos(psi0), foot[1] + zeta0 * math.sin(psi0)
    xdot, ydot = velocity[0], velocity[1]
    for k in range(cap):
        if y - zeta0 * math.sin(psi0) >= goal:
            return k, REACHED
        next_pitch = pitch_step(pitch, noise)
        next_psi0, next_zeta0 = perturbed_controls(schedule, k + 1, next_pitch, math.nan, noise)
        status, x, y, xdot, ydot, side, segment, _, _, _ = world_jump(
            x, y, xdot, ydot, side, segment, psi0, zeta0, next_psi0, next_zeta0, model, sides, no_record
        )
        if status != OK:
            return k, status
        if y < FLOOR_HEIGHT:
            return k, FLOOR
        xdot, ydot = disturbed_on_side(side, xdot, ydot, noise)
        pitch, psi0, zeta0 = next_pitch, next_psi0, next_zeta0
    return cap, OK


@kernel
def disturbed_on_side(side, xdot, ydot, noise):
    """The body's velocity at a touchdown on ``side`` (wall coordinates) with the velocity noise
    drawn in that side's stance frame, as the map's section state is disturbed."""
    mirror = 1.0 if side == 0 else -1.0
    flipped_xdot, ydot = disturbed_state(mirror * xdot, ydot, noise)
    return mirror * flipped_xdot, ydot


@kernel
def tallied_disturbed_on_side(side, xdot, ydot, noise, tally):
    """:func:`disturbed_on_side`, its draws tallied in ``tally``
    (:func:`sim_core.model.noise_rules.tallied_draw`: a followed plan's, importance-sampled)."""
    mirror = 1.0 if side == 0 else -1.0
    flipped_xdot, ydot = tallied_disturbed_state(mirror * xdot, ydot, noise, tally)
    return mirror * flipped_xdot, ydot


@parallel_kernel
def world_trials_batch(foot, velocity, segment, schedule, seeds, cap, goal, noise, model, sides, jumps, status):
    """:func:`world_trial` for each seed on all cores."""
    for i in prange(seeds.size):
        jumps[i], status[i] = world_trial(foot, velocity, segment, schedule, seeds[i], cap, goal, noise, model, sides)
