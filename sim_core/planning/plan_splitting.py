"""How long a plan lasts when it is climbed again and again: the chance that one climb of it fails,
by adaptive multilevel splitting where failures are rare, and the mean jumps to failure it gives
(docs/worlds.md, "The MFPT of a plan").

A lab runs a plan on the table many times over: each attempt starts at the plan's first
touchdown and ends at the goal or at a failure, its noise fresh. The attempts are independent, so
the number of them up to the first failure is geometric, and by Wald's identity the mean jumps to
failure are ``E[jumps of an attempt] / p`` with ``p`` the chance that an attempt fails — exact,
whatever the attempts' lengths. ``E[jumps]`` is an average any Monte-Carlo of attempts gives;
``p`` is the rare one.

``p`` by adaptive multilevel splitting (:mod:`sim_core.robustness.ams`): ``N`` attempts run to
their end; an attempt's *level* is the largest score it reached (its danger: how near its landings
come to a foothold's ends or its cone's edge, :mod:`sim_core.planning.attempts`), a failure's
infinite; the attempts at the lowest level are replaced by branches of survivors, cloned whole
(the trial, the plan it follows, its row and replans) and continued with numba's generator
reseeded from the estimate's own seed, until every one has failed. Independent runs give a t
interval on ``p`` and, through it, on the mean jumps to failure.

What it can and cannot do (docs/worlds.md, "The MFPT of a plan"): splitting gains where an
attempt passes through touchdowns ever nearer failing; a plan's attempt is a handful of jumps, and
at low noise its failures are decided within one jump's draws from touchdowns that look like any
other — nothing to split at. There, every run goes extinct (``p`` 0, said so) and Monte-Carlo
(:func:`plan_monte_carlo`, 0.3 ms an attempt without replanning) or importance sampling of the
draws that decide (:mod:`sim_core.planning.plan_importance`) is the estimate.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np
from scipy.stats import t as student_t

from sim_core.control.laws.placement import PlacementSettings
from sim_core.model.noise import NoiseModel
from sim_core.model.params import ModelParams
from sim_core.model.validation import check_range
from sim_core.planning.attempts import Attempt, Attempts
from sim_core.planning.follow import MAX_REPLANS
from sim_core.planning.planner import Plan
from sim_core.robustness.ams import ams_chance
from sim_core.world.world import World


@dataclass(frozen=True)
class PlanSplitting:
    """The estimate's size: ``replicas`` attempts a run, ``runs`` independent runs (for the
    interval), ``seed`` (run ``r``'s first attempts draw seeds ``seed + r * replicas + i``, its
    continuations their own), at most ``max_levels`` levels a run (then the run stops where it is,
    still unbiased), ``cap`` jumps an attempt at most (one at the cap has not failed), and the
    replans an attempt may make (the foothold study's 3 by default; 0 follows the plan alone)."""

    replicas: int = 40
    runs: int = 64  # fewer: the runs' estimates are skewed, and a t interval over 8 missed (docs/worlds.md)
    seed: int = 0
    max_levels: int = 20_000
    cap: int = 200
    max_replans: int = MAX_REPLANS

    def __post_init__(self) -> None:
        check_range("replicas", self.replicas, 2, 10_000, low_open=False, high_open=False)
        check_range("runs", self.runs, 2, 1_000, low_open=False, high_open=False)
        check_range("seed", self.seed, 0, 2**31, low_open=False)
        check_range("max_levels", self.max_levels, 1, 10**7, low_open=False, high_open=False)
        check_range("cap", self.cap, 1, 100_000, low_open=False, high_open=False)
        check_range("max_replans", self.max_replans, 0, 100, low_open=False, high_open=False)


@dataclass(frozen=True)
class PlanMfpt:
    """The estimate: ``failure_chance`` (``p``, the mean over runs) and its 95% t interval, the mean
    jumps of an attempt (over every run's first attempts: plain Monte-Carlo), ``mfpt_jumps`` =
    that / ``p`` and its interval (None where ``p`` is 0), each run's ``p`` and levels, seconds."""

    failure_chance: float
    failure_chance_ci95: tuple[float, float]
    mean_attempt_jumps: float
    mfpt_jumps: float | None
    mfpt_ci95: tuple[float, float | None] | None
    run_chances: tuple[float, ...]
    run_levels: tuple[int, ...]
    options: PlanSplitting
    seconds: float

    def to_dict(self) -> dict:
        return {
            "failure_chance": self.failure_chance,
            "failure_chance_ci95": list(self.failure_chance_ci95),
            "mean_attempt_jumps": self.mean_attempt_jumps,
            "mfpt_jumps": self.mfpt_jumps,
            "ci95": None if self.mfpt_ci95 is None else list(self.mfpt_ci95),
            "splitting": {
                "runs_failure_chance": list(self.run_chances),
                "runs_levels": list(self.run_levels),
                "replicas": self.options.replicas,
                "runs": self.options.runs,
                "seed": self.options.seed,
                "max_replans": self.options.max_replans,
                "cap": self.options.cap,
            },
            "seconds": self.seconds,
        }


def _splitting_run(follower: Attempts, options: PlanSplitting, run: int) -> tuple[float, int, list[int]]:
    """One AMS run (:func:`sim_core.robustness.ams.ams_chance`): ``(p, levels, the first attempts' jumps)``."""
    rng = np.random.default_rng((options.seed, run))
    first_seed = options.seed + run * options.replicas
    attempts = [follower.start(first_seed + i) for i in range(options.replicas)]
    jumps = [attempt.jumps for attempt in attempts]

    def branch(parent: Attempt, floor: float) -> tuple[Attempt, float]:
        cut = parent.cut(floor)
        if cut is None:  # passed the level only by failing: copied whole
            return parent, parent.level
        continued = follower.run(cut, int(rng.integers(2**31)), reseed=True)
        return continued, continued.level

    chance, levels = ams_chance(attempts, [attempt.level for attempt in attempts], branch, rng, options.max_levels)
    return chance, levels, jumps


def plan_mfpt(
    model: ModelParams,
    world: World,
    plan: Plan,
    goal: float,
    noise: NoiseModel,
    options: PlanSplitting = PlanSplitting(),
    *,
    settings: PlacementSettings | None = None,
    progress=None,
) -> PlanMfpt:
    """The chance that an attempt at ``plan`` (followed by the placement law, replanning as
    ``options`` allows) fails before a foot at ``goal`` [l0], and the mean jumps to failure of
    attempts made again and again. ``progress(done, total)`` after each run."""
    started = time.perf_counter()
    follower = Attempts(model, world, plan, goal, noise, settings, max_replans=options.max_replans, cap=options.cap)
    chances, levels, jumps = [], [], []
    for run in range(options.runs):
        chance, run_levels, run_jumps = _splitting_run(follower, options, run)
        chances.append(chance)
        levels.append(run_levels)
        jumps.extend(run_jumps)
        if progress is not None:
            progress(run + 1, options.runs)
    p = float(np.mean(chances))
    half = float(student_t.ppf(0.975, len(chances) - 1)) * float(np.std(chances, ddof=1)) / math.sqrt(len(chances))
    interval = (max(p - half, 0.0), p + half)
    mean_jumps = float(np.mean(jumps))
    mfpt = mean_jumps / p if p > 0.0 else None
    mfpt_interval = None
    if mfpt is not None:
        mfpt_interval = (mean_jumps / interval[1], mean_jumps / interval[0] if interval[0] > 0.0 else None)
    return PlanMfpt(p, interval, mean_jumps, mfpt, mfpt_interval, tuple(chances), tuple(levels), options,
                    time.perf_counter() - started)  # fmt: skip


@dataclass(frozen=True)
class PlanMonteCarlo:
    """Plain attempts, to check the splitting where they can tell: ``failures`` of ``trials``, the
    chance with its exact (Clopper-Pearson) 95% interval, the mean jumps of an attempt and the
    mean jumps to failure they give (None without a failure), seconds."""

    trials: int
    failures: int
    failure_chance_ci95: tuple[float, float]
    mean_attempt_jumps: float
    seconds: float

    @property
    def failure_chance(self) -> float:
        return self.failures / self.trials

    def to_dict(self) -> dict:
        chance = self.failure_chance
        return {
            "trials": self.trials,
            "failures": self.failures,
            "failure_chance": chance,
            "failure_chance_ci95": list(self.failure_chance_ci95),
            "mean_attempt_jumps": self.mean_attempt_jumps,
            "mfpt_jumps": self.mean_attempt_jumps / chance if chance > 0.0 else None,
            "seconds": self.seconds,
        }


def plan_monte_carlo(
    model: ModelParams,
    world: World,
    plan: Plan,
    goal: float,
    noise: NoiseModel,
    options: PlanSplitting,
    trials: int,
    first_seed: int,
    *,
    settings: PlacementSettings | None = None,
    progress=None,
) -> PlanMonteCarlo:
    """``trials`` attempts from seeds ``first_seed ..`` (each :func:`sim_core.planning.follow.follow_plan`'s
    trial of its seed, replans and cap as ``options``), counted."""
    from scipy.stats import beta

    check_range("trials", trials, 1, 10**6, low_open=False, high_open=False)
    started = time.perf_counter()
    follower = Attempts(model, world, plan, goal, noise, settings, max_replans=options.max_replans, cap=options.cap)
    failures, jumps = 0, 0
    for i in range(trials):
        attempt = follower.start(first_seed + i)
        failures += attempt.failed
        jumps += attempt.jumps
        if progress is not None and (i + 1) % 100 == 0:
            progress(i + 1, trials)
    low = float(beta.ppf(0.025, failures, trials - failures + 1)) if failures else 0.0
    high = float(beta.ppf(0.975, failures + 1, trials - failures)) if failures < trials else 1.0
    return PlanMonteCarlo(trials, failures, (low, high), jumps / trials, time.perf_counter() - started)
