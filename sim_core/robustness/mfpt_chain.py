"""The MFPT chain of one grid, built and solved: noisy paths find where the chain must be fine
(:func:`explore`), the compiled kernels give every state's jumps (:func:`build_chain`), and the
sparse solvers its expected jumps to failure and its largest eigenvalue. The estimate around it
(start, two grids, the result) is :mod:`sim_core.robustness.mfpt`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from sim_core.chunks import Progress
from sim_core.model.noise import NoiseModel
from sim_core.model.validation import ParameterError
from sim_core.robustness.mfpt_grid import (
    ChainGrid,
    check_pairs,
    check_states,
    kept_states,
    pitch_axis,
    pitch_stencil,
    quadrature,
    velocity_axis,
)

PAIRS_PER_CHUNK = 20_000
SOLVE_TOLERANCE = 1e-10  # relative residual of (I - P) m = r
SOLVE_ITERATIONS = 3_000
DIRECT_SOLVE_STATES = 5_000  # factored directly below this size, and with one pitch layer at any
EXPLORE_SEED = 20090601  # the exploring paths' generator: the grid depends on it, the chain's noise does not


@dataclass(frozen=True)
class Chain:
    """One grid's chain. Its transient states' matrix is the product ``P = steps @ jumps``: the
    pitch step from each state to the *pairs* (velocity node, pitch its leg sees), then each
    pair's noisy jump to the states it lands on. Kept as the two factors, ``P`` has a tenth of
    their product's entries to multiply (each pair is shared by the 17 pitch steps that reach
    it). ``success`` is the probability that each state's next jump succeeds."""

    xdots: np.ndarray
    ydots: np.ndarray
    pitches: np.ndarray
    state_of: np.ndarray  # (layers, ny * nx) -> state index, -1 outside the chain
    steps: object  # scipy.sparse.csr_matrix (states, pairs)
    jumps: object  # scipy.sparse.csr_matrix (pairs, states)
    success: np.ndarray
    escaped: float  # the largest probability of any state's jump landing outside the chain

    @property
    def states(self) -> int:
        return int(self.success.size)

    def transition_operator(self):
        """``P`` as a scipy LinearOperator (products through both factors)."""
        from scipy.sparse.linalg import LinearOperator

        return LinearOperator(
            (self.states, self.states),
            matvec=lambda x: self.steps @ (self.jumps @ x),
            rmatvec=lambda x: self.jumps.T @ (self.steps.T @ x),
            dtype=float,
        )

    def transitions(self):
        """``P`` as one sparse matrix (for a direct solve of a small chain)."""
        return (self.steps @ self.jumps).tocsr()


def noise_sigmas(noise: NoiseModel) -> tuple[float, float, float, float]:
    """The chain's standard deviations ``(psi0 [rad], zeta0 [l0], velocity [sqrt(g l0)], pitch step
    [rad])`` (the asymmetry offsets are refused by :mod:`sim_core.robustness.mfpt`)."""
    record = noise.record()
    return record.sigma_psi0, record.sigma_zeta0, record.sigma_velocity, record.sigma_pitch


def first_landings(model, controls, noise, start, points):
    """The first jump's quadrature: its landings on the mid-chute section (n, 3), their status
    and weights."""
    from sim_core.model.noisy_map import first_jumps

    sigma_psi0, sigma_zeta0, _, _ = noise_sigmas(noise)
    draws, weights = quadrature((sigma_psi0, sigma_zeta0), points)
    states = np.empty((draws.shape[0], 3))
    status = np.empty(draws.shape[0], dtype=np.int64)
    first_jumps(float(start[0]), float(start[1]), controls.psi0, controls.zeta0, draws, model.record(), states, status)
    return states, status, weights


def explore(model, controls, noise, start, grid: ChainGrid) -> np.ndarray:
    """States (n, 3) the noisy paths visit on the mid-chute section, from the first jump's landings."""
    from sim_core.model.noisy_map import first_jumps, sampled_paths

    sigma_psi0, sigma_zeta0, sigma_velocity, sigma_pitch = noise_sigmas(noise)
    rng = np.random.default_rng(EXPLORE_SEED)
    leg = rng.standard_normal((grid.paths, 2)) * [sigma_psi0, sigma_zeta0]
    starts = np.empty((grid.paths, 3))
    status = np.empty(grid.paths, dtype=np.int64)
    first_jumps(float(start[0]), float(start[1]), controls.psi0, controls.zeta0, leg, model.record(), starts, status)
    starts = starts[status == 0]
    if starts.shape[0] == 0:
        raise ParameterError("controls", "every first jump from the start fails: nothing to build a chain on")
    scales = np.array([sigma_pitch, sigma_psi0, sigma_zeta0, sigma_velocity, sigma_velocity])
    draws = rng.standard_normal((starts.shape[0], grid.path_jumps, 5)) * scales
    visited = np.empty((starts.shape[0], grid.path_jumps, 3))
    steps = np.empty(starts.shape[0], dtype=np.int64)
    sampled_paths(starts, controls.psi0, controls.zeta0, draws, model.record(), visited, steps)
    visited = visited.reshape(-1, 3)
    return np.concatenate([starts, visited[np.isfinite(visited[:, 0])]])


def build_chain(model, controls, noise, start, grid: ChainGrid, progress: Progress | None = None) -> Chain:
    """The chain of one grid: its axes and states from :func:`explore`, then every transition."""
    from scipy import sparse

    from sim_core.model.noisy_map import CORNERS, pair_transitions

    sigma_psi0, sigma_zeta0, sigma_velocity, sigma_pitch = noise_sigmas(noise)
    visited = explore(model, controls, noise, start, grid)
    center = np.median(visited[:, :2], axis=0)
    xdots = velocity_axis(visited[:, 0], grid.velocity_nodes, center[0], grid.half_width, floor=1e-3)
    ydots = velocity_axis(visited[:, 1], grid.velocity_nodes, center[1], grid.half_width, floor=-math.inf)
    pitch_spacing = grid.pitch_spacing * sigma_pitch
    pitches = pitch_axis(visited[:, 2], sigma_pitch, pitch_spacing)
    kept = kept_states(visited, xdots, ydots, pitches, grid.margin)
    layers, nodes = pitches.size, xdots.size * ydots.size
    check_states(int(kept.sum()))
    kept = kept.reshape(layers, nodes)
    state_of = np.full((layers, nodes), -1, dtype=np.int64)
    state_of[kept] = np.arange(int(kept.sum()))

    # The states' pitch steps: from layer i the coming leg sees layer (layers - 1 - i) + offset,
    # and each (velocity node, layer seen) is one *pair* whose jump the kernel runs once.
    offsets, step_weights = pitch_stencil(sigma_pitch, pitch_spacing if sigma_pitch > 0 else 1.0)
    mirrored = kept[::-1]
    needed = np.zeros_like(kept)
    for offset in offsets:
        if offset >= 0:
            needed[offset:] |= mirrored[: layers - offset]
        else:
            needed[:offset] |= mirrored[-offset:]
    pair_layers, pair_nodes = np.nonzero(needed)
    check_pairs(pair_layers.size, grid.max_pairs)
    pair_of = np.full((layers, nodes), -1, dtype=np.int64)
    pair_of[pair_layers, pair_nodes] = np.arange(pair_layers.size)

    strata = grid.strata_for(sigma_pitch > 0.0)
    draws, draw_weights = quadrature((sigma_psi0, sigma_zeta0, sigma_velocity, sigma_velocity), strata)
    width = draws.shape[0] * CORNERS
    pieces, failed, escaped = [], np.empty(pair_layers.size), np.empty(pair_layers.size)
    chunks = range(0, pair_layers.size, PAIRS_PER_CHUNK)
    for done, first in enumerate(chunks, start=1):
        part = slice(first, min(first + PAIRS_PER_CHUNK, pair_layers.size))
        count = part.stop - part.start
        cols = np.empty((count, width), dtype=np.int64)
        probabilities = np.empty((count, width))
        counts = np.empty(count, dtype=np.int64)
        pair_transitions(
            pair_nodes[part], pair_layers[part], xdots, ydots, pitches, state_of, controls.psi0, controls.zeta0,
            draws, draw_weights, model.record(), cols, probabilities, counts, failed[part], escaped[part],
        )  # fmt: skip
        used = np.arange(width) < counts[:, None]
        rows = np.repeat(np.arange(count), counts)
        pieces.append(sparse.csr_matrix((probabilities[used], (rows, cols[used])), shape=(count, int(kept.sum()))))
        if progress is not None:
            progress(done, len(chunks))
    pair_matrix = sparse.vstack(pieces, format="csr") if pieces else sparse.csr_matrix((0, int(kept.sum())))

    # States -> pairs: the pitch step's weights (a step off the pitch grid is lost, as a failure).
    state_layers, state_nodes = np.nonzero(kept)
    rows, cols, weights = [], [], []
    for offset, weight in zip(offsets, step_weights, strict=True):
        seen = layers - 1 - state_layers + offset
        inside = (seen >= 0) & (seen < layers)
        rows.append(np.nonzero(inside)[0])
        cols.append(pair_of[seen[inside], state_nodes[inside]])
        weights.append(np.full(int(inside.sum()), weight))
    steps = sparse.csr_matrix(
        (np.concatenate(weights), (np.concatenate(rows), np.concatenate(cols))),
        shape=(state_layers.size, pair_layers.size),
    )
    success = steps @ (1.0 - failed)
    lost = steps @ escaped + (1.0 - np.asarray(steps.sum(axis=1)).ravel())
    return Chain(xdots, ydots, pitches, state_of, steps, pair_matrix, success, float(lost.max(initial=0.0)))


def expected_jumps(chain: Chain) -> np.ndarray:
    """Each state's expected jumps before absorption: ``(I - P) m = r``.

    A chain of one pitch layer (no drift) is two-dimensional and factors directly in a second;
    it is also where the MFPT runs to millions of jumps and iterative solvers crawl. A chain
    with pitch layers fills in badly when factored (100 s for 23,000 states) but needs only a
    few dozen BiCGSTAB products with ``P`` where its MFPT is hundreds of jumps; LGMRES is the
    second try.
    """
    from scipy import sparse
    from scipy.sparse.linalg import LinearOperator, bicgstab, lgmres, spsolve

    if chain.pitches.size == 1 or chain.states <= DIRECT_SOLVE_STATES:
        direct = (sparse.identity(chain.states, format="csc") - chain.transitions()).tocsc()
        return np.asarray(spsolve(direct, chain.success), dtype=float)
    transitions = chain.transition_operator()
    system = LinearOperator(transitions.shape, matvec=lambda x: x - transitions @ x, dtype=float)
    scale = max(float(np.linalg.norm(chain.success)), 1e-300)
    for solver in (bicgstab, lgmres):
        values, info = solver(system, chain.success, rtol=SOLVE_TOLERANCE, atol=0.0, maxiter=SOLVE_ITERATIONS)
        if info == 0 and np.linalg.norm(system @ values - chain.success) <= 10 * SOLVE_TOLERANCE * scale:
            return np.asarray(values, dtype=float)
    raise ParameterError(
        "grid",
        f"the chain's {chain.states:,} states did not solve to {SOLVE_TOLERANCE:g} in {SOLVE_ITERATIONS} "
        "iterations (an MFPT far beyond Monte-Carlo's with the pitch drifting); use a coarser grid",
    )


def largest_eigenvalue(chain: Chain) -> float:
    """``λ₂``: the transient matrix's eigenvalue of largest modulus (real, by Perron–Frobenius)."""
    from scipy.sparse.linalg import ArpackNoConvergence, eigs

    if chain.states < 3:
        return float(np.max(np.abs(np.linalg.eigvals(chain.transitions().toarray()))))
    try:
        values = eigs(
            chain.transition_operator(), k=1, which="LM", return_eigenvectors=False, maxiter=20_000, tol=1e-12
        )
    except ArpackNoConvergence as error:  # keep what converged; none: not known
        values = error.eigenvalues
        if values.size == 0:
            return math.nan
    return float(np.real(values[0]))
