"""The holding state of a closed loop, measured on its compiled runs: what the splitting estimate
(:mod:`sim_core.robustness.splitting`) starts from.

A long run from the climb's start (its first :data:`SETTLE_JUMPS` left out; a failure starts it
again) gives the features' mean and covariance per wall, hence the score, the Mahalanobis distance
from holding (:mod:`sim_core.robustness.splitting_kernels`). Home is ``score < a`` and an exit the first
``score >= b`` after home, ``a`` and ``b`` quantiles of the run's scores; ``T_loop`` is the
run's jumps per exit (its sampling error shows in the spread of :mod:`sim_core.robustness.splitting`'s
independent runs). The climb from the start to home is measured on its own short runs: their
mean length and the share that fail before home.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from sim_core.control.laws import Controller
from sim_core.control.loop_step import LOOP_STATE_SIZE
from sim_core.model.failures import OK, Failure
from sim_core.model.noise import NoiseModel
from sim_core.model.params import ModelParams
from sim_core.model.validation import ParameterError
from sim_core.robustness.splitting_kernels import TOO_LONG, excursion, features_table, long_run, scores_of, started

SETTLE_JUMPS = 50  # the climb's first jumps, left out of the holding state's statistics
MIN_EXITS = 30  # a long run with fewer exits than this cannot measure T_loop


@dataclass(frozen=True)
class Holding:
    """The score (per-wall ``mean`` and ``whitening``), the ``home`` and ``exit`` levels, the
    exits the long run recorded (loop states and touchdown indices), ``T_loop`` [jumps], the long
    run's restarts after a failure, and the climb: its mean
    jumps to home (a failed climb counted to its failure) and the share failing before home."""

    mean: np.ndarray
    whitening: np.ndarray
    home: float
    exit: float
    exit_states: np.ndarray
    exit_touchdowns: np.ndarray
    loop_jumps: float
    pilot_failures: int
    climb_jumps: float
    climb_failures: float


class Loop:
    """One controller's compiled loop under one noise: what every run of it takes. ``limit`` is
    the longest excursion [jumps]."""

    def __init__(self, model: ModelParams, controller: Controller, noise: NoiseModel, limit: int):
        self.kind, self.parameters = controller.kernel_args()
        self.psi0 = math.radians(controller.psi0_deg)
        self.target = controller.target
        self.noise = noise.record()
        self.model = model.record()
        self.limit = limit
        self.path = np.empty((limit, LOOP_STATE_SIZE))  # reused: each excursion is copied out
        self.scores = np.empty(limit)

    def start(self, start, start_zeta0: float, rng: np.random.Generator) -> np.ndarray:
        """The loop at its first touchdown, as the control study starts it."""
        return started(self.kind, start[0], start[1], self.psi0, start_zeta0, _seed(rng), self.noise)

    def run(self, state: np.ndarray, touchdown: int, jumps: int, rng: np.random.Generator) -> tuple[int, np.ndarray]:
        """``jumps`` more touchdowns from ``state`` (advanced in place): ``(status, states reached)``."""
        states = np.empty((jumps, LOOP_STATE_SIZE))
        status, done = long_run(
            state, touchdown, self.kind, self.parameters, _seed(rng), self.noise, self.model, states
        )
        return status, states[:done]

    def excursion(self, state: np.ndarray, touchdown: int, holding: Holding, rng: np.random.Generator):
        """From touchdown ``touchdown`` until home or a failure: ``(states, touchdown indices,
        scores, level)``, the start included; ``level`` is the highest score, infinite on a failure."""
        home = (holding.mean, holding.whitening, holding.home)
        status, done = excursion(state.copy(), touchdown, self.kind, self.parameters, _seed(rng), self.noise,
                                 self.model, self.target, *home, self.path, self.scores)  # fmt: skip
        if status == TOO_LONG:
            raise ParameterError("excursion_limit", f"an excursion neither failed nor came home in {self.limit} jumps")
        first = scores_of(state[None, :], touchdown, self.target, holding.mean, holding.whitening)
        scores = np.concatenate([first, self.scores[:done]])
        level = math.inf if status != OK else float(scores.max())
        return np.concatenate([state[None, :], self.path[:done]]), touchdown + np.arange(done + 1), scores, level


def measure_holding(
    loop: Loop, start, start_zeta0: float, pilot_jumps: int, quantiles: tuple[float, float], climbs: int, rng
) -> Holding:
    """The holding state from a long run of ``pilot_jumps`` touchdowns after the settle, home and
    exit at ``quantiles`` of its scores, and ``climbs`` climbs from the start to home.

    Raises:
        ParameterError: the run fails too often to hold, or leaves home too rarely to count loops.
    """
    pieces, failures, recorded = [], 0, 0
    while recorded < pilot_jumps:
        state = loop.start(start, start_zeta0, rng)
        status, _ = loop.run(state, 0, SETTLE_JUMPS, rng)
        if status == OK:
            status, states = loop.run(state, SETTLE_JUMPS, pilot_jumps - recorded, rng)
            if states.shape[0]:
                pieces.append((states, SETTLE_JUMPS + 1))
                recorded += states.shape[0]
        if status != OK:
            failures += 1
            if failures > max(10, pilot_jumps // 50):
                raise ParameterError("noise", f"the loop fails too often to hold ({failures} failures, the last "
                                     f"{Failure(status).code}, in its long run): Monte-Carlo measures it")  # fmt: skip
    mean, whitening = _whitening(pieces, loop.target)
    scores = [scores_of(states, k0, loop.target, mean, whitening) for states, k0 in pieces]
    home, exit_level = (float(level) for level in np.quantile(np.concatenate(scores), quantiles))
    exits, touchdowns = [], []
    for (states, k0), score in zip(pieces, scores, strict=True):
        at = _exits(score, home, exit_level)
        exits.append(states[at])
        touchdowns.append(k0 + at)
    count = sum(at.size for at in touchdowns)
    if count < MIN_EXITS:
        raise ParameterError("pilot_jumps", f"the long run left home {count} times: at least {MIN_EXITS} needed")
    holding = Holding(mean, whitening, home, exit_level, np.concatenate(exits), np.concatenate(touchdowns),
                      recorded / count, failures,
                      math.nan, math.nan)  # fmt: skip
    return _with_climb(loop, holding, start, start_zeta0, climbs, rng)


def _with_climb(loop: Loop, holding: Holding, start, start_zeta0: float, climbs: int, rng) -> Holding:
    lengths, failed = [], 0
    for _ in range(climbs):
        _, touchdowns, _, level = loop.excursion(loop.start(start, start_zeta0, rng), 0, holding, rng)
        lengths.append(touchdowns[-1])
        failed += math.isinf(level)
    return replace(holding, climb_jumps=float(np.mean(lengths)), climb_failures=failed / climbs)


def _seed(rng: np.random.Generator) -> int:
    return int(rng.integers(2**32))


def _whitening(pieces, target: float) -> tuple[np.ndarray, np.ndarray]:
    """Per wall (touchdown parity): the features' mean and ``W`` with ``|W d|^2 = d' C^+ d``;
    a direction the run never varies is left out."""
    features = np.concatenate([features_table(states, target) for states, _ in pieces])
    sides = np.concatenate([(k0 + np.arange(len(states))) % 2 for states, k0 in pieces])
    mean, whitening = [], []
    for side in (0, 1):
        rows = features[sides == side]
        mean.append(rows.mean(axis=0))
        values, vectors = np.linalg.eigh(np.cov(rows, rowvar=False))
        kept = values > 1e-12 * values.max()
        scale = np.where(kept, 1.0 / np.sqrt(np.where(kept, values, 1.0)), 0.0)
        whitening.append(scale[:, None] * vectors.T)
    return np.array(mean), np.array(whitening)


def _exits(scores: np.ndarray, home: float, exit_level: float) -> np.ndarray:
    """Indices where the run first reaches ``exit_level`` after being home."""
    at, at_home = [], False
    for j, score in enumerate(scores):
        if score < home:
            at_home = True
        elif at_home and score >= exit_level:
            at.append(j)
            at_home = False
    return np.array(at, dtype=np.int64)
