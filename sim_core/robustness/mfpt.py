"""Mean first-passage time (MFPT) of a noisy gait: a Markov chain on the Poincaré section
(Byl & Tedrake, "Metastable walking machines", IJRR 2009; the paper's reference [28]).

Monte-Carlo MJTF (:mod:`sim_core.robustness.mjtf`) counts jumps until each trial fails, so a robust gait
needs as many jumps as it survives, and a capped study scores every good gait the same. The chain
instead discretises the noisy jump map once: states on the mid-chute section ``(xdot, ydot,
pitch)`` (:mod:`sim_core.robustness.mfpt_grid`, :mod:`sim_core.model.noisy_map`), failure absorbing. The
expected number of jumps before absorption ``m`` solves ``(I - P) m = r`` (``P`` the transient
states' transition matrix, ``r`` the probability that a state's next jump succeeds), and the
largest eigenvalue ``λ₂`` of ``P`` (the second of the chain with its absorbing state, whose first
is 1) gives the time scale ``1 / (1 - λ₂)`` of leaving the quasi-stationary distribution. Its
accuracy is the grid's: :func:`mfpt` solves on two grids, one refined from the other, and reports
their relative difference as the discretisation error. Each grid's chain is cached on disk
(:mod:`sim_core.robustness.mfpt_cache`), so asking again for the same gait, noise and grids only solves.

What it models is exactly MJTF's trial (docs/model.md §5): from the gait's touchdown at zero
pitch, the first leg's controls noisy, then per jump a pitch step, the next leg's noisy controls
and the velocity disturbance. The MFPT it returns counts jumps completed, as MJTF does.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, replace

import numpy as np

from sim_core.chunks import Progress
from sim_core.model.controls import ControlSchedule, LegControl
from sim_core.model.noise import NoiseModel
from sim_core.model.params import ModelParams
from sim_core.model.validation import ParameterError
from sim_core.robustness.mfpt_cache import ChainCache, chain_key, enabled
from sim_core.robustness.mfpt_chain import Chain, build_chain, expected_jumps, first_landings, largest_eigenvalue
from sim_core.robustness.mfpt_grid import ChainGrid


@dataclass(frozen=True)
class MfptEstimate:
    """One grid's answer: MFPT from the start [jumps], ``λ₂``, the chain's size and time, and
    whether its chain was loaded from the cache rather than built."""

    mfpt_jumps: float
    lambda2: float
    states: int
    escaped: float
    seconds: float
    grid: ChainGrid
    cached: bool = False


@dataclass(frozen=True)
class MfptResult:
    """The MFPT on the finer of two grids, with the coarser one's difference as its error.

    Attributes:
        mfpt_jumps: expected jumps completed from the start before a failure, as MJTF counts them.
        lambda2: the chain's largest eigenvalue below 1; ``1 / (1 - lambda2)`` the metastable
            time scale [jumps].
        discretisation_error: ``|fine - coarse| / fine`` of the two grids' MFPT.
        cells: states of the finer chain.
        seconds: wall time of both grids together (this call's, cached chains or not).
        estimates: (coarse, fine).
    """

    controls: LegControl
    noise: NoiseModel
    start: np.ndarray
    mfpt_jumps: float
    lambda2: float
    discretisation_error: float
    cells: int
    seconds: float
    estimates: tuple[MfptEstimate, ...]

    @property
    def lambda2_jumps(self) -> float:
        return math.inf if self.lambda2 >= 1.0 else 1.0 / (1.0 - self.lambda2)

    def to_dict(self) -> dict:
        """The ``parkour mfpt --json`` contract."""
        return {
            "mfpt_jumps": self.mfpt_jumps,
            "lambda2": self.lambda2,
            "lambda2_jumps": self.lambda2_jumps,
            "discretisation_error": self.discretisation_error,
            "cells": self.cells,
            "seconds": self.seconds,
            "controls": {"psi0_deg": self.controls.psi0_deg, "zeta0": self.controls.zeta0},
            "noise": self.noise.to_dict(),
            "start": self.start.tolist(),
            "cached": [estimate.cached for estimate in self.estimates],
            "grids": [
                {
                    **estimate.grid.to_dict(),
                    "mfpt_jumps": estimate.mfpt_jumps,
                    "lambda2": estimate.lambda2,
                    "cells": estimate.states,
                    "escaped": estimate.escaped,
                    "seconds": estimate.seconds,
                    "cached": estimate.cached,
                }
                for estimate in self.estimates
            ],
        }


def check_chain_inputs(model: ModelParams, noise: NoiseModel) -> None:
    """What the chain cannot represent, refused naming the field."""
    if model.d_hat <= 2.0:
        raise ParameterError("d_hat", f"the chain's mid-chute section needs d_hat > 2, got {model.d_hat:g}")
    for field in ("asymmetry_psi0_deg", "asymmetry_zeta0"):
        if getattr(noise, field) != 0.0:
            raise ParameterError(
                f"noise.{field}", "must be 0 for the MFPT chain (an L/R asymmetry needs the wall in the state)"
            )


def mfpt(
    model: ModelParams,
    controls: LegControl,
    noise: NoiseModel,
    *,
    start=None,
    grid: ChainGrid | None = None,
    progress: Progress | None = None,
    cache: ChainCache | bool = True,
) -> MfptResult:
    """MFPT of symmetric controls under ``noise``, from the touchdown state ``start`` (default:
    the gait's fixed point, as MJTF starts) at zero pitch, on ``grid`` and on the grid one step
    coarser (whose difference is the reported error). ``cache``: True for the default chain
    cache (unless ``$PARKOUR_MFPT_CACHE=0``), False for none, or a :class:`ChainCache`.

    Raises:
        ParameterError: noise the chain cannot represent, a grid too large, a bad start.
        FixedPointNotFound: no gait to start from when ``start`` is not given.
    """
    check_chain_inputs(model, noise)
    grid = grid or ChainGrid()
    start = _start_state(model, controls, start)
    chains = cache if isinstance(cache, ChainCache) else ChainCache() if cache and enabled() else None
    began = time.perf_counter()
    grid = replace(grid, strata=grid.strata_for(noise.pitch_drift_deg > 0.0))
    coarse_grid = grid.refined(1.0 / math.sqrt(2.0))
    estimates = []
    for index, each in enumerate((coarse_grid, grid)):
        report = None if progress is None else _stage_progress(progress, index)
        estimates.append(solve_on(model, controls, noise, start, each, report, chains))
    coarse, fine = estimates
    error = abs(fine.mfpt_jumps - coarse.mfpt_jumps) / fine.mfpt_jumps if fine.mfpt_jumps > 0 else math.nan
    return MfptResult(
        controls,
        noise,
        start,
        fine.mfpt_jumps,
        fine.lambda2,
        error,
        fine.states,
        time.perf_counter() - began,
        tuple(estimates),
    )


def _stage_progress(progress: Progress, stage: int) -> Progress:
    def report(done: int, total: int) -> None:
        progress(stage * total + done, 2 * total)

    return report


def _start_state(model: ModelParams, controls: LegControl, start) -> np.ndarray:
    if start is None:
        from sim_core.section.gait_search import gait_of

        return np.asarray(gait_of(model, ControlSchedule((controls,))).state, dtype=float)
    state = np.asarray(start, dtype=float)
    if state.shape != (2,) or not np.all(np.isfinite(state)) or state[0] >= 0.0:
        raise ParameterError("start", f"must be a touchdown state (xdot < 0, ydot), got {start!r}")
    return state


def solve_on(
    model: ModelParams,
    controls: LegControl,
    noise: NoiseModel,
    start: np.ndarray,
    grid: ChainGrid,
    progress: Progress | None = None,
    cache: ChainCache | None = None,
) -> MfptEstimate:
    """MFPT and ``λ₂`` on one grid, its chain from ``cache`` when there (and stored when built)."""
    began = time.perf_counter()
    key = None if cache is None else chain_key(model, controls, noise, start, grid)
    chain = None if key is None else cache.load(key)
    cached = chain is not None
    if chain is None:
        chain = build_chain(model, controls, noise, start, grid, progress)
        if key is not None:
            cache.store(key, chain)
    elif progress is not None:
        progress(1, 1)
    values = expected_jumps(chain)
    mfpt_jumps = first_jump_value(model, controls, noise, start, grid, chain, values)
    return MfptEstimate(
        mfpt_jumps, largest_eigenvalue(chain), chain.states, chain.escaped, time.perf_counter() - began, grid, cached
    )


def first_jump_value(model, controls, noise, start, grid: ChainGrid, chain: Chain, values: np.ndarray) -> float:
    """MFPT from the start: the first jump's quadrature, each landing worth 1 (the jump) plus the
    chain's value there, shared among its cell's nodes on the zero-pitch layer."""
    from sim_core.model.noisy_map import axis_cell

    landings, status, weights = first_landings(
        model, controls, noise, start, grid.strata_for(noise.pitch_drift_deg > 0.0)[:2]
    )
    zero = (chain.pitches.size - 1) // 2
    total = 0.0
    nx = chain.xdots.size
    for (x, y, _), ok, weight in zip(landings, status, weights, strict=True):
        if ok != 0:
            continue
        ix, tx = axis_cell(x, chain.xdots)
        iy, ty = axis_cell(y, chain.ydots)
        value = 0.0
        if ix >= 0 and iy >= 0:
            for dy, wy in ((0, 1.0 - ty), (1, ty)):
                for dx, wx in ((0, 1.0 - tx), (1, tx)):
                    state = chain.state_of[zero, (iy + dy) * nx + ix + dx]
                    if state >= 0:
                        value += wx * wy * values[state]
        total += weight * (1.0 + value)
    return float(total)
