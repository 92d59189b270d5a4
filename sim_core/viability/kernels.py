"""The viability engine's compiled loops (:mod:`sim_core.viability.engine`): the fixed point of the
viable set and the measure of each pair, over flat arrays.

``bins`` is (pairs, ds) int, the bin each pair reaches per state dimension (``0 .. n``: nodes
``i - 1`` and ``i`` around it); pairs are ordered state-major (``pair = state * actions +
action``) and states in C order of ``state_shape``.
"""

from __future__ import annotations

from numba import prange

from sim_core._jit import kernel, parallel_kernel


@kernel
def _corners_viable(bin_index, kernel_mask, state_shape):
    """Whether every existing grid node at the corners of the bin ``bin_index`` (per dimension,
    nodes ``i - 1`` and ``i``) is in the kernel."""
    dimensions = state_shape.size
    for corner in range(1 << dimensions):
        flat = 0
        inside = True
        for d in range(dimensions):
            node = bin_index[d] - 1 + ((corner >> d) & 1)
            if node < 0 or node >= state_shape[d]:
                inside = False
                break
            flat = flat * state_shape[d] + node
        if inside and not kernel_mask[flat]:
            return False
    return True


@kernel
def _project(viable, kernel_mask, actions):
    """``kernel_mask[s]``: whether state ``s`` has a viable action."""
    for s in range(kernel_mask.size):
        kernel_mask[s] = False
        for a in range(actions):
            if viable[s * actions + a]:
                kernel_mask[s] = True
                break


@kernel
def shrink(bins, viable, kernel_mask, state_shape, actions):
    """Drop pairs that reach outside the kernel until nothing changes (in place); the sweeps done."""
    _project(viable, kernel_mask, actions)
    sweeps = 0
    changed = True
    while changed:
        changed = False
        sweeps += 1
        for pair in range(viable.size):
            if viable[pair] and not _corners_viable(bins[pair], kernel_mask, state_shape):
                viable[pair] = False
                changed = True
        _project(viable, kernel_mask, actions)
    return sweeps


@parallel_kernel
def pair_measures(bins, viable, measure, state_shape, out):
    """vibly's ``Q_M``: for each viable pair the mean measure of the existing nodes around the bin it reaches."""
    dimensions = state_shape.size
    for pair in prange(viable.size):
        if not viable[pair]:
            out[pair] = 0.0
            continue
        total, nodes = 0.0, 0
        for corner in range(1 << dimensions):
            flat = 0
            inside = True
            for d in range(dimensions):
                node = bins[pair, d] - 1 + ((corner >> d) & 1)
                if node < 0 or node >= state_shape[d]:
                    inside = False
                    break
                flat = flat * state_shape[d] + node
            if inside:
                total += measure[flat]
                nodes += 1
        out[pair] = total / nodes if nodes > 0 else 0.0
