"""The compiled runs of the splitting estimate (:mod:`sim_core.robustness.splitting`): a loop's distance from
its holding state (the score), a long run that samples that state, and an excursion away from it.

A run is :func:`sim_core.control.loop_step.loop_jump` repeated on a copy of the loop's whole state, seeded
once per call (a continued excursion draws fresh noise from its own seed). The score of a
touchdown is the Mahalanobis distance of its features (section state, controls, height error)
from the holding state's mean, per wall: ``|W (f - mean)|`` with ``W`` the
whitening of the features' covariance, measured on a long run.
"""

from __future__ import annotations

import math

import numpy as np

from sim_core._jit import kernel
from sim_core.control.loop_step import LOOP_STATE_SIZE, PSI0, XDOT, YDOT, ZETA0, body_height, loop_jump, start_loop
from sim_core.model.failures import OK
from sim_core.model.integrate import STATE_SIZE
from sim_core.model.noise_rules import seed_trial

FEATURES = 5  # xdot, ydot, psi0, zeta0, height error
TOO_LONG = -1  # an excursion that neither failed nor came back within its buffer


@kernel
def features_of(state, target, out):
    """The score's features of a touchdown into ``out``: the section state and the controls that
    set its jump, and the height error [l0]. Not the law's memory: a PID's integral moves slowly,
    and a score that waits on it comes home too rarely to count loops."""
    out[0], out[1], out[2], out[3] = state[XDOT], state[YDOT], state[PSI0], state[ZETA0]
    out[4] = body_height(state) - target


@kernel
def score_of(state, k, target, mean, whitening, work):
    """Distance of touchdown ``k``'s loop state from the holding state (wall ``k % 2``'s mean and
    whitening)."""
    features_of(state, target, work)
    side = k % 2
    total = 0.0
    for i in range(FEATURES):
        projected = 0.0
        for j in range(FEATURES):
            projected += whitening[side, i, j] * (work[j] - mean[side, j])
        total += projected * projected
    return math.sqrt(total)


@kernel
def started(kind, xdot, ydot, first_psi0, first_zeta0, seed, noise):
    """The loop's state at its first touchdown (:func:`sim_core.control.loop_step.start_loop`), its
    first leg's noise (``noise``: a :class:`sim_core.model.noise.NoiseRecord`) drawn from ``seed``."""
    seed_trial(seed)
    state = np.empty(LOOP_STATE_SIZE)
    start_loop(state, kind, xdot, ydot, first_psi0, first_zeta0, noise)
    return state


@kernel
def long_run(state, k, kind, parameters, seed, noise, model, states):
    """Continue the loop from touchdown ``k`` (``state``, advanced in place) for up to
    ``states.shape[0]`` jumps, recording each touchdown reached; ``noise`` and ``model`` are the
    records of the noise and the model. Returns ``(status, jumps done)``."""
    seed_trial(seed)
    no_record = np.empty((0, STATE_SIZE))
    for j in range(states.shape[0]):
        status, _ = loop_jump(state, k + j, kind, parameters, noise, model, no_record)
        if status != OK:
            return status, j
        states[j] = state
    return OK, states.shape[0]


@kernel
def excursion(state, k, kind, parameters, seed, noise, model, target, mean, whitening, level, path, scores):
    """Continue the loop from touchdown ``k`` until its score falls below ``level`` (back home),
    it fails, or ``path`` is full; ``path`` and ``scores`` get each touchdown reached. Returns
    ``(OK, jumps)`` when back, ``(failure status, jumps before it)``, or ``(TOO_LONG, jumps)``."""
    seed_trial(seed)
    no_record = np.empty((0, STATE_SIZE))
    work = np.empty(FEATURES)
    for j in range(path.shape[0]):
        status, _ = loop_jump(state, k + j, kind, parameters, noise, model, no_record)
        if status != OK:
            return status, j
        path[j] = state
        scores[j] = score_of(state, k + j + 1, target, mean, whitening, work)
        if scores[j] < level:
            return OK, j + 1
    return TOO_LONG, path.shape[0]


@kernel
def scores_of(states, k0, target, mean, whitening):
    """The score of each recorded touchdown, the first being touchdown ``k0``."""
    work = np.empty(FEATURES)
    out = np.empty(states.shape[0])
    for j in range(states.shape[0]):
        out[j] = score_of(states[j], k0 + j, target, mean, whitening, work)
    return out


@kernel
def features_table(states, target):
    """The features of each recorded touchdown, shape ``(n, FEATURES)``."""
    out = np.empty((states.shape[0], FEATURES))
    for j in range(states.shape[0]):
        features_of(states[j], target, out[j])
    return out
