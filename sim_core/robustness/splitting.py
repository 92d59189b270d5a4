"""Mean first-passage time of a closed loop by splitting: rare failures of a controller that holds
its height, without a grid.

A law's loop has more state than a section grid can hold (section state, the controls in flight,
the height error, the law's memory), so its MFPT is estimated on the compiled loop itself, by the
Hill relation and adaptive multilevel splitting (AMS: Cérou & Guyader 2007; for an MFPT, Lopes &
Lelièvre 2019):

1. The holding state (:mod:`sim_core.robustness.splitting_holding`): a score, the distance from holding;
   home (``score < a``), exits (a first ``score >= b`` after home) and ``T_loop``, the mean jumps
   between exits, on a long run; the climb from the start to home on short runs.
2. ``p``, the chance that an exit fails before it comes home, by AMS: ``replicas`` excursions from
   the recorded exits; all that rose least are dropped, each replaced by a copy of a survivor cut
   where it first passed that level and continued with fresh noise (copied whole when it passed
   the level only by failing), until every replica has failed; ``p`` is the product of the
   survivors' shares. Unbiased whatever the score (the score sets the variance).
3. From home, failures arrive at rate ``p / T_loop`` (the Hill relation). ``runs`` independent
   runs each do 1 and 2 (each its own long run, so the interval counts its sampling too); with
   ``r`` the runs' mean rate, ``MFPT = climb + (1 - climb failures) / r`` with a t interval on
   ``r``, and ``lambda2 = 1 - r``, the second eigenvalue of a metastable loop's chain. (The Hill
   relation's ``T_loop / p`` leaves out the failing excursion's own length: small where p is.)

A loop is metastable only without pitch drift: with it the pitch's random walk, unbounded, sets
the failures when it reaches the leg's range (``parkour control-study`` measures those runs).
"""

from __future__ import annotations

import math
import time
from dataclasses import asdict, dataclass

import numpy as np
from scipy.stats import t as student_t

from sim_core.chunks import Progress
from sim_core.control.laws import Controller
from sim_core.model.noise import NoiseModel
from sim_core.model.params import ModelParams
from sim_core.model.validation import ParameterError, check_range
from sim_core.robustness.ams import ams_chance
from sim_core.robustness.splitting_holding import Holding, Loop, measure_holding


@dataclass(frozen=True)
class SplittingOptions:
    """How hard the estimate works: ``runs`` independent runs, each with its own long run of
    ``pilot_jumps``, home and exit at quantiles of its scores, ``climbs`` climbs measured and one
    AMS of ``replicas``; the longest excursion [jumps]; the seed of every draw."""

    replicas: int = 100
    runs: int = 64  # many runs, fewer replicas: p's spread over runs is skewed, its interval needs them
    pilot_jumps: int = 5_000
    home_quantile: float = 0.5
    exit_quantile: float = 0.9
    climbs: int = 4
    excursion_limit: int = 20_000
    seed: int = 0

    def __post_init__(self) -> None:
        check_range("replicas", self.replicas, 2, 10_000, low_open=False, high_open=False)
        check_range("runs", self.runs, 2, 1_000, low_open=False, high_open=False)
        check_range("pilot_jumps", self.pilot_jumps, 1_000, 10_000_000, low_open=False, high_open=False)
        check_range("home_quantile", self.home_quantile, 0.0, 1.0)
        check_range("exit_quantile", self.exit_quantile, self.home_quantile, 1.0)
        check_range("climbs", self.climbs, 1, 100_000, low_open=False, high_open=False)
        check_range("excursion_limit", self.excursion_limit, 100, 10_000_000, low_open=False, high_open=False)
        check_range("seed", self.seed, 0, 2**32, low_open=False, high_open=True)


@dataclass(frozen=True)
class LoopMfpt:
    """A controller's MFPT [jumps] from the climb's start, its 95% interval, and how it was got."""

    controller: str
    target: float  # [l0]
    noise: NoiseModel
    mfpt_jumps: float
    ci95: tuple[float, float]
    probabilities: tuple[float, ...]  # p of each run: an exit fails before it comes home
    holdings: tuple[Holding, ...]  # each run's holding state
    seconds: float
    options: SplittingOptions

    @property
    def rate(self) -> float:
        """Failures per jump from home: the runs' mean of ``p / T_loop``."""
        return float(np.mean([p / h.loop_jumps for p, h in zip(self.probabilities, self.holdings, strict=True)]))

    @property
    def lambda2_jumps(self) -> float:
        """``1 / (1 - lambda2) = T_loop / p``: the MFPT from home."""
        return 1.0 / self.rate if self.rate > 0 else math.inf

    @property
    def failure_free_jumps(self) -> int:
        """Jumps the runs' long runs held with no failure at all (each ``pilot_jumps``), or 0 if one failed."""
        if any(holding.pilot_failures for holding in self.holdings):
            return 0
        return len(self.holdings) * self.options.pilot_jumps

    @property
    def mfpt_at_least(self) -> float | None:
        """Where no run reached a failure: the MFPT's 95% lower bound from the jumps held with none
        (``n / ln 20``: a mean of ``m`` jumps gives no failure in ``n`` with chance ``exp(-n / m)``
        at most, below 5% for ``m`` under it); None where the estimate is finite or a long run failed."""
        if math.isfinite(self.mfpt_jumps) or not self.failure_free_jumps:
            return None
        return self.failure_free_jumps / math.log(20.0)

    @property
    def relative_error(self) -> float:
        """Half the 95% interval over the estimate."""
        return 0.5 * (self.ci95[1] - self.ci95[0]) / self.mfpt_jumps

    def to_dict(self) -> dict:
        """``parkour mfpt --controller ... --json``: the chain's keys (no grid: ``cells`` and
        ``discretisation_error`` are null; an MFPT no run could reach is null, and then
        ``mfpt_at_least_jumps`` bounds it from the jumps held with no failure) and the splitting's."""
        finite = math.isfinite(self.mfpt_jumps)
        holdings = self.holdings
        return {
            "mfpt_jumps": self.mfpt_jumps if finite else None,
            "mfpt_at_least_jumps": self.mfpt_at_least,
            "failure_free_jumps": self.failure_free_jumps,
            "lambda2": 1.0 - 1.0 / self.lambda2_jumps,
            "lambda2_jumps": self.lambda2_jumps if finite else None,
            "discretisation_error": None,
            "relative_error": self.relative_error if math.isfinite(self.relative_error) else None,
            "ci95": [bound if math.isfinite(bound) else None for bound in self.ci95] if finite else None,
            "cells": None,
            "seconds": self.seconds,
            "method": "splitting",
            "controller": self.controller,
            "noise": self.noise.to_dict(),
            "splitting": {
                "rate": self.rate,
                "probabilities": list(self.probabilities),
                "loop_jumps": [holding.loop_jumps for holding in holdings],
                "climb_jumps": _mean(holding.climb_jumps for holding in holdings),
                "climb_failures": _mean(holding.climb_failures for holding in holdings),
                "exits": [int(holding.exit_states.shape[0]) for holding in holdings],
                "home_score": _mean(holding.home for holding in holdings),
                "exit_score": _mean(holding.exit for holding in holdings),
                "pilot_failures": sum(holding.pilot_failures for holding in holdings),
                **asdict(self.options),
            },
        }


def check_metastable(noise: NoiseModel) -> None:
    """Refuse what splitting cannot estimate, naming the field."""
    if noise.pitch_drift_deg != 0.0:
        raise ParameterError(
            "noise.pitch_drift_deg",
            "must be 0 for a controller's MFPT: with pitch drift the loop is not metastable (the pitch's random "
            "walk reaches the leg's range); parkour control-study measures its mean jumps to failure",
        )
    if noise.velocity == 0.0 and noise.psi0_deg == 0.0 and noise.zeta0 == 0.0:
        raise ParameterError("noise", "needs some noise: a noiseless loop that holds never fails")


def loop_mfpt(
    model: ModelParams,
    controller: Controller,
    start,
    start_zeta0: float,
    noise: NoiseModel,
    options: SplittingOptions | None = None,
    progress: Progress | None = None,
) -> LoopMfpt:
    """MFPT of ``controller``'s loop started as the control study starts it (section state
    ``start``, the first leg at the law's nominal angle and ``start_zeta0``), under ``noise``.

    Raises:
        ParameterError: pitch drift or no noise (:func:`check_metastable`), a long run that fails
            too often or leaves home too rarely to measure, an excursion past ``excursion_limit``.
    """
    check_metastable(noise)
    options = options or SplittingOptions()
    began = time.perf_counter()
    rng = np.random.default_rng(options.seed)
    loop = Loop(model, controller, noise, options.excursion_limit)
    quantiles = (options.home_quantile, options.exit_quantile)
    holdings, probabilities = [], []
    for run in range(options.runs):  # each run its own long run: the interval counts its sampling too
        holding = measure_holding(loop, start, start_zeta0, options.pilot_jumps, quantiles, options.climbs, rng)
        holdings.append(holding)
        probabilities.append(failure_probability(loop, holding, options.replicas, rng))
        if progress is not None:
            progress(run + 1, options.runs)
    rates = np.array([p / holding.loop_jumps for p, holding in zip(probabilities, holdings, strict=True)])
    climb = _mean(holding.climb_jumps for holding in holdings)
    survives = 1.0 - _mean(holding.climb_failures for holding in holdings)
    rate = float(rates.mean())
    if rate == 0.0:
        mfpt, ci95 = math.inf, (math.inf, math.inf)
    else:
        half = float(student_t.ppf(0.975, options.runs - 1) * rates.std(ddof=1) / math.sqrt(options.runs))
        mfpt = climb + survives / rate
        ci95 = (climb + survives / (rate + half), climb + survives / (rate - half) if rate > half else math.inf)
    return LoopMfpt(controller.name, controller.target, noise, mfpt, ci95, tuple(probabilities), tuple(holdings),
                    time.perf_counter() - began, options)  # fmt: skip


def _mean(values) -> float:
    return float(np.mean(list(values)))


def failure_probability(loop: Loop, holding: Holding, replicas: int, rng: np.random.Generator) -> float:
    """One AMS run of ``replicas``: the chance that an exit fails before it comes home (0 when
    every replica came home at the same highest level, which no copy can pass)."""
    picks = rng.integers(holding.exit_states.shape[0], size=replicas)
    paths = [loop.excursion(holding.exit_states[i], int(holding.exit_touchdowns[i]), holding, rng) for i in picks]

    def branch(parent, floor):
        states, touchdowns, scores, level = parent
        above = scores > floor
        if not above.any():  # the survivor crossed the level by failing: the copy fails with it
            return parent, level
        cut = int(np.argmax(above))  # the survivor's first touchdown past the level
        on_states, on_touchdowns, on_scores, level = loop.excursion(states[cut], int(touchdowns[cut]), holding, rng)
        path = (
            np.concatenate([states[:cut], on_states]),
            np.concatenate([touchdowns[:cut], on_touchdowns]),
            np.concatenate([scores[:cut], on_scores]),
            level,  # the prefix stays at or below the floor, and the continuation starts above it
        )
        return path, level

    chance, _ = ams_chance(paths, [level for *_, level in paths], branch, rng)
    return chance
