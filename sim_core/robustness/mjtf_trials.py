"""MJTF's trials, compiled: one noisy run of a gait until it fails or reaches the cap, and a batch of
them on all cores (paper Fig. 11, docs/model.md §5).

A trial draws its disturbances in :mod:`sim_core.model.noise_rules`' order from its own seed — at each
lift-off a pitch step and the next leg's controls, after each jump the section state — so a trial's
outcome depends on its seed alone, not on the batch or the thread that runs it. The study around
them (levels, chunks, statistics) is :mod:`sim_core.robustness.mjtf`.
"""

from __future__ import annotations

import math

import numpy as np
from numba import prange

from sim_core._jit import kernel, parallel_kernel
from sim_core.model.failures import OK
from sim_core.model.integrate import STATE_SIZE
from sim_core.model.noise import NoiseModel
from sim_core.model.noise_rules import disturbed_state, perturbed_controls, pitch_step, seed_trial
from sim_core.model.params import ModelParams
from sim_core.model.stride import jump


def run_trials(
    model: ModelParams, schedule: np.ndarray, start, noise: NoiseModel, seeds: np.ndarray, cap: int
) -> tuple[np.ndarray, np.ndarray]:
    """One trial per seed from ``start``, on all cores: ``(jumps completed, status)`` arrays."""
    jumps = np.empty(seeds.size, dtype=np.int64)
    status = np.empty(seeds.size, dtype=np.int64)
    trials_batch(float(start[0]), float(start[1]), schedule, seeds, cap, noise.record(), model.record(), jumps, status)
    return jumps, status


# The noise and the model reach the kernels as one record each (NoiseModel.record(),
# ModelParams.record()), read by field: a new parameter is a new field, not a longer argument
# list to copy into every kernel that passes it on.
@kernel
def trial(xdot, ydot, schedule, seed, cap, noise, model):
    """One noisy run: ``(jumps completed, status of the failing jump or OK at the cap)``."""
    seed_trial(seed)
    no_record = np.empty((0, STATE_SIZE))
    pitch = 0.0
    psi0, zeta0 = perturbed_controls(schedule, 0, pitch, math.nan, noise)
    for k in range(cap):
        next_pitch = pitch_step(pitch, noise)
        next_psi0, next_zeta0 = perturbed_controls(schedule, k + 1, next_pitch, math.nan, noise)
        status, xdot, ydot, _, _, _, _ = jump(xdot, ydot, psi0, zeta0, next_psi0, next_zeta0, model, no_record)
        if status != OK:
            return k, status
        xdot, ydot = disturbed_state(xdot, ydot, noise)
        pitch, psi0, zeta0 = next_pitch, next_psi0, next_zeta0
    return cap, OK


@parallel_kernel
def trials_batch(xdot, ydot, schedule, seeds, cap, noise, model, jumps, status):
    """:func:`trial` for each seed on all cores."""
    for i in prange(seeds.size):
        jumps[i], status[i] = trial(xdot, ydot, schedule, seeds[i], cap, noise, model)
