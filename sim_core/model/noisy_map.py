"""The noisy jump map on the mid-chute section, compiled: one step, sampled paths, and the
transition probabilities of a grid's nodes (the Markov chain of :mod:`sim_core.robustness.mfpt`).

Why the mid-chute section. At a touchdown the body's state is ``(xdot, ydot)`` and the pitch, but
the leg that just touched down was set by noise drawn *before* the touchdown, and that draw also
moved where the touchdown happened: a chain on the touchdown section that draws the leg's noise
again double-counts it. Halfway between the walls (``x = 0`` after the flip) nothing of the
coming jump has been drawn yet, and the flight's horizontal speed is constant, so the state there
— the flight's ``(xdot, ydot)`` and the pitch — is all the future depends on. One step from it
draws, in :mod:`sim_core.model.noise_rules`' order, the pitch step and the next leg's controls, flies to
the wall, adds the velocity noise, runs the stance (:func:`sim_core.model.stride.lift_off`) and flies
back to the middle. ``d_hat > 2`` keeps both ends of every flight on their own side of the middle.

Pitch is kept in the frame of the wall the coming leg stands on: the body's pitch ``theta`` turns
the left wall's leg by ``+theta`` and the right wall's by ``-theta`` (docs/model.md §5), so with
``p`` the pitch as the last leg saw it, the next leg sees ``-p + draw``. The chain then needs no
wall parity (the asymmetry offsets, which do, are refused by :mod:`sim_core.robustness.mfpt`).
"""

from __future__ import annotations

import math

import numpy as np
from numba import prange

from sim_core._jit import kernel, parallel_kernel
from sim_core.model.failures import NO_FLIGHT, OK
from sim_core.model.integrate import STATE_SIZE
from sim_core.model.noise_rules import disturbed, noisy_controls
from sim_core.model.stride import lift_off

MATCHING_PASSES = 3  # fixed-point passes of matched_spread's shrink factor
CORNERS = 4  # the nodes a velocity inside the grid is shared among (bilinear weights)


@kernel
def to_middle(psi, liftoff_xdot, liftoff_ydot, d_hat):
    """From lift-off (leg angle ``psi`` [rad], body velocity) to the middle of the chute:
    ``(status, xdot, ydot)``, NO_FLIGHT where the body does not fly toward the other wall."""
    if not liftoff_xdot > 0.0:
        return NO_FLIGHT, math.nan, math.nan
    time = (0.5 * d_hat - math.cos(psi)) / liftoff_xdot
    return OK, liftoff_xdot, liftoff_ydot - time


@kernel
def middle_step(
    xdot,
    ydot,
    next_pitch,
    psi0,
    zeta0,
    psi0_draw,
    zeta0_draw,
    xdot_draw,
    ydot_draw,
    model,
    no_record,
):
    """One noisy jump from the middle of a flight to the middle of the next.

    Args:
        xdot, ydot: the flight's velocity at the middle [sqrt(g l0)] (``xdot > 0``: toward the wall).
        next_pitch: the pitch the coming leg sees, in its wall's frame [rad] (the last leg's
            pitch, negated, plus the step's pitch draw).
        psi0, zeta0: the commanded controls of the coming leg [rad, l0].
        psi0_draw ... ydot_draw: the step's other noise, already scaled.
        model: the model's record (:meth:`sim_core.model.params.ModelParams.record`).

    Returns:
        ``(status, xdot, ydot)`` at the next middle; NaNs after a failed stance or flight.
    """
    nan = math.nan
    psi, zeta = noisy_controls(psi0, zeta0, False, next_pitch, 0.0, 0.0, psi0_draw, zeta0_draw)
    time = (0.5 * model.d_hat - zeta * math.cos(psi)) / xdot
    touchdown_xdot, touchdown_ydot = disturbed(-xdot, ydot - time, xdot_draw, ydot_draw)
    status, psi_end, liftoff_xdot, liftoff_ydot, _, _ = lift_off(
        touchdown_xdot, touchdown_ydot, psi, zeta, model, no_record
    )
    if status != OK:
        return status, nan, nan
    return to_middle(psi_end, liftoff_xdot, liftoff_ydot, model.d_hat)


@kernel
def axis_cell(value, axis):
    """``(lower node, fraction past it)`` of ``value`` on a sorted, possibly non-uniform axis;
    node -1 outside it."""
    last = axis.size - 1
    if not (axis[0] <= value <= axis[last]):
        return -1, 0.0
    lower = min(np.searchsorted(axis, value, side="right") - 1, last - 1)
    return lower, (value - axis[lower]) / (axis[lower + 1] - axis[lower])


@kernel
def interpolation_variance(value, axis):
    """The variance that sharing ``value`` between its two nodes adds on ``axis``: ``t (1 - t) h²``."""
    lower, fraction = axis_cell(value, axis)
    if lower < 0:
        return 0.0
    spacing = axis[lower + 1] - axis[lower]
    return fraction * (1.0 - fraction) * spacing * spacing


@kernel
def matched_spread(values, weights, ok, axis):
    """Pull the landings ``values`` toward their mean so that their variance plus the variance
    that sharing them among nodes adds is their own variance (moment matching; in place).
    Sharing a point between two nodes keeps its mean but adds ``t (1 - t) h²``; without this a
    grid of spacing ``h`` diffuses like velocity noise of that size every jump, and a chain whose
    core nodes are 0.04 apart failed twice as soon as the noise it models (the MFPT at zeta0 0.96
    49 jumps, Monte-Carlo 95)."""
    total = 0.0
    mean = 0.0
    for s in range(values.size):
        if ok[s]:
            total += weights[s]
            mean += weights[s] * values[s]
    if total <= 0.0:
        return
    mean /= total
    variance = 0.0
    for s in range(values.size):
        if ok[s]:
            variance += weights[s] * (values[s] - mean) ** 2
    variance /= total
    if variance <= 0.0:
        return
    shrink = 1.0
    for _ in range(MATCHING_PASSES):  # the added variance depends on where the shrunk points land
        added = 0.0
        for s in range(values.size):
            if ok[s]:
                added += weights[s] * interpolation_variance(mean + shrink * (values[s] - mean), axis)
        shrink = math.sqrt(max(0.0, 1.0 - added / total / variance))
    for s in range(values.size):
        if ok[s]:
            values[s] = mean + shrink * (values[s] - mean)


@parallel_kernel
def pair_transitions(
    pair_nodes, pair_layers, xdots, ydots, pitches, state_of, psi0, zeta0, draws, draw_weights, model,
    cols, probabilities, counts, failed, escaped,
):  # fmt: skip
    """The noisy jump from each *pair*: a velocity node of the grid (``pair_nodes``: ``ix + iy *
    nx`` on the axes ``xdots``, ``ydots``) with the coming leg at the pitch of layer
    ``pair_layers`` (``pitches``, in that leg's wall frame).

    The noise of the step but the pitch's is the rule ``draws`` (S, 4: psi0, zeta0, xdot, ydot,
    scaled) with weights ``draw_weights`` (summing to 1). The velocities reached, their spread
    matched to the nodes (:func:`matched_spread`), are each shared among their cell's 4 nodes
    (bilinear weights) on the same layer: the pitch the leg saw is the state's pitch.
    ``state_of`` (layers, nx * ny) numbers the grid's states (-1: not in the chain).

    Outputs, per pair ``p``: ``cols[p, :counts[p]]`` and ``probabilities[p, :counts[p]]``, the
    states reached (sorted, merged); ``failed[p]`` the probability that the jump fails;
    ``escaped[p]`` that it lands on a node outside the chain.
    """
    nx = xdots.size
    width = cols.shape[1]
    samples = draws.shape[0]
    for pair in prange(pair_nodes.size):
        no_record = np.empty((0, STATE_SIZE))
        node, layer = pair_nodes[pair], pair_layers[pair]
        x, y = xdots[node % nx], ydots[node // nx]
        landed_x = np.empty(samples)
        landed_y = np.empty(samples)
        ok = np.zeros(samples, dtype=np.bool_)
        lost = 0.0
        for s in range(samples):
            status, landed_x[s], landed_y[s] = middle_step(
                x, y, pitches[layer], psi0, zeta0, draws[s, 0], draws[s, 1], draws[s, 2], draws[s, 3], model, no_record
            )
            ok[s] = status == OK
            if not ok[s]:
                lost += draw_weights[s]
        matched_spread(landed_x, draw_weights, ok, xdots)
        matched_spread(landed_y, draw_weights, ok, ydots)
        local_cols = np.empty(width, dtype=np.int64)
        local_probabilities = np.empty(width)
        used = 0
        out = 0.0
        for s in range(samples):
            if not ok[s]:
                continue
            mass = draw_weights[s]
            ix, tx = axis_cell(landed_x[s], xdots)
            iy, ty = axis_cell(landed_y[s], ydots)
            if ix < 0 or iy < 0:
                out += mass
                continue
            for corner in range(CORNERS):
                dx, dy = corner & 1, corner >> 1
                share = mass * (tx if dx else 1.0 - tx) * (ty if dy else 1.0 - ty)
                if share == 0.0:
                    continue
                state = state_of[layer, (iy + dy) * nx + ix + dx]
                if state < 0:
                    out += share
                    continue
                local_cols[used] = state
                local_probabilities[used] = share
                used += 1
        order = np.argsort(local_cols[:used], kind="mergesort")
        kept = 0
        for j in range(used):
            col = local_cols[order[j]]
            if kept > 0 and cols[pair, kept - 1] == col:
                probabilities[pair, kept - 1] += local_probabilities[order[j]]
            else:
                cols[pair, kept] = col
                probabilities[pair, kept] = local_probabilities[order[j]]
                kept += 1
        counts[pair] = kept
        failed[pair] = lost
        escaped[pair] = out


@parallel_kernel
def first_jumps(xdot, ydot, psi0, zeta0, draws, model, states, status):
    """The first jump of a trial, as MJTF starts one (docs/model.md §5): from the touchdown
    ``(xdot, ydot)`` at zero pitch, the leg's controls noisy, no velocity noise, to the middle of
    its flight. ``draws`` (n, 2) are the leg's draws (psi0, zeta0, scaled); ``states`` (n, 3)
    and ``status`` (n,) out."""
    for s in prange(draws.shape[0]):
        no_record = np.empty((0, STATE_SIZE))
        psi, zeta = noisy_controls(psi0, zeta0, False, 0.0, 0.0, 0.0, draws[s, 0], draws[s, 1])
        result, psi_end, liftoff_xdot, liftoff_ydot, _, _ = lift_off(xdot, ydot, psi, zeta, model, no_record)
        if result == OK:
            result, states[s, 0], states[s, 1] = to_middle(psi_end, liftoff_xdot, liftoff_ydot, model.d_hat)
        states[s, 2] = 0.0
        status[s] = result


@parallel_kernel
def sampled_paths(starts, psi0, zeta0, draws, model, visited, steps):
    """Noisy paths from each start (n, 3: xdot, ydot, pitch) for at most ``draws.shape[1]`` steps
    (``draws`` (n, steps, 5): pitch step, psi0, zeta0, xdot, ydot, scaled): ``visited`` (n,
    steps, 3) gets the states reached (NaN after a failure), ``steps`` (n,) how many steps each
    path completed."""
    for i in prange(starts.shape[0]):
        no_record = np.empty((0, STATE_SIZE))
        x, y, p = starts[i, 0], starts[i, 1], starts[i, 2]
        visited[i, :, :] = math.nan
        steps[i] = draws.shape[1]
        for k in range(draws.shape[1]):
            p = -p + draws[i, k, 0]
            status, x, y = middle_step(
                x, y, p, psi0, zeta0, draws[i, k, 1], draws[i, k, 2], draws[i, k, 3], draws[i, k, 4], model, no_record
            )
            if status != OK:
                steps[i] = k
                break
            visited[i, k, 0], visited[i, k, 1], visited[i, k, 2] = x, y, p
