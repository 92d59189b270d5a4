"""A plan's rare failure chance by importance sampling of its climbs' draws (docs/worlds.md, "The
MFPT of a plan"): where failures are too rare for splitting (:mod:`sim_core.planning.plan_splitting`)
and cost Monte-Carlo 10^5 climbs to see a handful.

Every draw of a climb's noise is a zero-mean Gaussian (:mod:`sim_core.model.noise_rules`: the pitch
step, the leg's ``psi0`` and ``zeta0``, the velocity's two components). The climbs are drawn from a
*proposal*: the same noise with the standard deviations of the ``scaled`` kinds of draw (all, by
default) multiplied by ``scale`` (s > 1: failures become common), each climb from its own seed in
the order plain Monte-Carlo draws, and weighed by its draws' likelihood ratio. A draw ``z = s sigma
u`` (``u`` standard normal under the proposal) has ``p(z) / q(z) = s exp(-u^2 (s^2 - 1) / 2)``, so
a climb whose scaled draws number ``n`` and whose ``u^2`` sum to ``U`` weighs ``w = s^n exp(-(s^2 -
1) U / 2)`` — ``n`` and ``U`` by kind are tallied by the compiled loop itself
(:func:`sim_core.model.noise_rules.tallied_draw`). The chance is ``mean(w * failed)``, unbiased for
any ``s >= 1``; its standard error the sample's. At ``s = 1`` the climbs are plain Monte-Carlo's of
the same seeds (:func:`sim_core.planning.plan_splitting.plan_monte_carlo`), every weight 1.

The replans plan for the true noise: the robot's planner is part of what is estimated, the same
under either distribution; only the physics' draws are widened.

Its limit: every scaled draw widens the weights' spread, those that decide nothing too
(``E_q[w^2] = (s^2 / sqrt(2 s^2 - 1))^n`` over ``n`` draws: 1.20 a draw at s = 1.5, 1.51 at s = 2).
A climb of 4 jumps draws 22 times; where one of them decides its failure (at low noise, touchdown
0's ``psi0``: the plan's first leg, sent before the law sees the robot; docs/worlds.md), scaling all
22 leaves a few climbs carrying the whole weight and the estimate falls short (typically) of the
truth. Scale only the kind that decides (``scaled=("psi0",)``), and only touchdown 0's draws
(``first_leg_only``: the jumps after draw from the noise itself). The effective sample size
``(sum w)^2 / sum w^2`` of all climbs and of the failing climbs' weights (the effective failures)
say how degenerate the weights are; the result carries a warning where they are small.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from sim_core.control.laws.placement import PlacementSettings
from sim_core.model.errors import ParameterError
from sim_core.model.noise import NoiseModel, NoiseRecord
from sim_core.model.noise_rules import TALLY_KINDS, TALLY_SIZE
from sim_core.model.params import ModelParams
from sim_core.model.validation import check_range
from sim_core.planning.attempts import Attempts
from sim_core.planning.follow import CAPPED, JUMP, REACHED, REPLAN, TALLY, TRIAL_SIZE, follow, replanned, start_trial
from sim_core.planning.plan_splitting import PlanSplitting
from sim_core.planning.planner import Plan
from sim_core.world.world import World

SCALE_LIMITS = (1.0, 5.0)  # the proposal's scale; at 5 each widened draw already multiplies E[w^2] by 3.6
Z95 = 1.959963984540054  # the standard normal's 97.5% quantile
# Fewer effective failures: the sample's standard error is itself a guess (at noise × 0.2, psi0's draws
# × 2.5 gave 43 and an interval that left out Monte-Carlo's chance from 800,000 climbs: docs/worlds.md)
MIN_EFFECTIVE_FAILURES = 50.0
MIN_EFFECTIVE_SHARE = 0.01  # an effective sample size below 1% of the climbs: degenerate (warned)


def kind_scales(scale: float, scaled=TALLY_KINDS) -> np.ndarray:
    """Each kind's scale (:data:`sim_core.model.noise_rules.TALLY_KINDS`' order): ``scale`` for the
    ``scaled`` kinds, 1 for the others; checked, naming ``scale`` or ``scaled``."""
    check_range("scale", scale, *SCALE_LIMITS, low_open=False, high_open=False)
    unknown = sorted(set(scaled) - set(TALLY_KINDS))
    if unknown or not scaled:
        raise ParameterError("scaled", f"must be some of {', '.join(TALLY_KINDS)}, got {', '.join(scaled) or 'none'}")
    return np.array([float(scale) if kind in scaled else 1.0 for kind in TALLY_KINDS])


def proposal(noise: NoiseModel, scales: np.ndarray) -> NoiseRecord:
    """``noise`` as the compiled kernels take it, each kind's standard deviation multiplied by its
    of ``scales`` (the asymmetries are offsets, not draws: kept). At scales 1 it is
    ``noise.record()`` exactly, so the climbs are plain Monte-Carlo's."""
    record = noise.record()
    return record._replace(**{f"sigma_{kind}": float(scale) * getattr(record, f"sigma_{kind}")
                              for kind, scale in zip(TALLY_KINDS, scales, strict=True)})  # fmt: skip


@dataclass(frozen=True)
class ImportanceClimbs:
    """Climbs drawn from the proposal (``scale`` on the ``scaled`` kinds, of touchdown 0 alone where
    ``first_leg_only``), one row each: ``failed``, its ``jumps``, the ``tallies`` of its draws from
    the proposal (:func:`sim_core.model.noise_rules.tallied_draw`'s layout: by kind, the draws and
    the sum of their squares as standard normals; a kind not scaled weighs 1 whatever its tally)."""

    failed: np.ndarray  # (climbs,) bool
    jumps: np.ndarray  # (climbs,) int
    tallies: np.ndarray  # (climbs, TALLY_SIZE)
    scale: float
    scaled: tuple[str, ...]
    first_leg_only: bool = False

    @property
    def log_weights(self) -> np.ndarray:
        """Each climb's ``log(p / q)`` of its draws: over the kinds, ``n log s - (s^2 - 1) U / 2``."""
        scales = kind_scales(self.scale, self.scaled)
        draws, squares = self.tallies[:, 0::2], self.tallies[:, 1::2]
        return draws @ np.log(scales) - squares @ (0.5 * (scales**2 - 1.0))

    @property
    def weights(self) -> np.ndarray:
        return np.exp(self.log_weights)


def importance_climbs(
    model: ModelParams,
    world: World,
    plan: Plan,
    goal: float,
    noise: NoiseModel,
    options: PlanSplitting,
    trials: int,
    first_seed: int,
    scale: float,
    *,
    scaled: tuple[str, ...] = TALLY_KINDS,
    first_leg_only: bool = False,
    settings: PlacementSettings | None = None,
    progress=None,
) -> ImportanceClimbs:
    """``trials`` climbs of ``plan`` to a foot at ``goal`` [l0] from seeds ``first_seed ..``, each as
    :func:`sim_core.planning.follow.follow_plan`'s trial of its seed (replans and cap as ``options``)
    drawing from :func:`proposal`: the ``scaled`` kinds' sigmas × ``scale`` — at touchdown 0 alone
    where ``first_leg_only`` (the plan's first leg, sent before the law sees the robot; the jumps
    after draw from ``noise``). ``progress(done, trials)`` every 100."""
    check_range("trials", trials, 2, 10**6, low_open=False, high_open=False)  # 2: a sample's standard error
    scaled = tuple(scaled)
    widened = proposal(noise, kind_scales(scale, scaled))
    start_noise, jump_noise = (widened, noise.record()) if first_leg_only else (widened, widened)
    follower = Attempts(model, world, plan, goal, noise, settings, max_replans=options.max_replans, cap=options.cap)
    failed, jumps = np.zeros(trials, dtype=bool), np.zeros(trials, dtype=np.int64)
    tallies = np.zeros((trials, TALLY_SIZE))
    for i in range(trials):
        failed[i], jumps[i], tally = _climb(follower, first_seed + i, start_noise, jump_noise)
        tallies[i] = tally[0] if first_leg_only else tally[1]
        if progress is not None and (i + 1) % 100 == 0:
            progress(i + 1, trials)
    return ImportanceClimbs(failed, jumps, tallies, float(scale), scaled, first_leg_only)


def _climb(follower: Attempts, seed: int, start_noise: NoiseRecord, jump_noise: NoiseRecord):
    """One climb: :func:`sim_core.planning.follow.follow_plan`'s loop (the replans plan for the true
    noise: the robot's planner is part of what is estimated), touchdown 0 drawn from ``start_noise``,
    the jumps from ``jump_noise``. Returns ``(failed, jumps, (touchdown 0's tally, the whole climb's))``."""
    trial, first = np.empty(TRIAL_SIZE), follower.first
    start_trial(trial, follower.aims, *first.target, first.segment, *first.velocity, seed, start_noise)
    start_tally = trial[TALLY:].copy()
    aims, row, replans = follower.aims, 0, 0
    while True:
        outcome, row = follow(trial, aims, row, follower.goal, follower.cap, replans < follower.max_replans, jump_noise,
                              follower.record, follower.sides, follower.settings)  # fmt: skip
        if outcome != REPLAN:
            return outcome not in (REACHED, CAPPED), int(trial[JUMP]), (start_tally, trial[TALLY:])
        fresh = replanned(follower.model, follower.world, follower.goal, trial, follower.noise, seed)
        if fresh is None:  # no way on from here: the law aims at what it had, without replanning again
            replans = follower.max_replans
        else:
            aims, row, replans = fresh, 0, replans + 1


@dataclass(frozen=True)
class PlanImportance:
    """The estimate: ``failure_chance`` (``mean(w * failed)``), its ``standard_error`` and normal 95%
    interval (upper None where no climb failed under the proposal: it cannot tell); the effective
    sample size of all weights and of the failing climbs' (``effective_failures``); the ``failures``
    under the proposal of ``trials`` climbs (``scale`` on the ``scaled`` kinds, of touchdown 0 alone
    where ``first_leg_only``); the mean jumps of
    a climb (the weights normalised) and the mean jumps to failure they give; ``warning`` where the
    weights are too degenerate to trust the interval (else None); seconds."""

    trials: int
    scale: float
    scaled: tuple[str, ...]
    first_leg_only: bool
    failures: int
    failure_chance: float
    standard_error: float
    failure_chance_ci95: tuple[float, float | None]
    effective_sample_size: float
    effective_failures: float
    mean_attempt_jumps: float
    warning: str | None
    seconds: float

    @property
    def relative_error(self) -> float | None:
        """The standard error over the chance (None at a chance of 0)."""
        return self.standard_error / self.failure_chance if self.failure_chance > 0.0 else None

    def to_dict(self) -> dict:
        chance = self.failure_chance
        return {
            "trials": self.trials,
            "scale": self.scale,
            "scaled": list(self.scaled),
            "first_leg_only": self.first_leg_only,
            "failures_under_proposal": self.failures,
            "failure_chance": chance,
            "standard_error": self.standard_error,
            "relative_error": self.relative_error,
            "failure_chance_ci95": list(self.failure_chance_ci95),
            "effective_sample_size": self.effective_sample_size,
            "effective_failures": self.effective_failures,
            "mean_attempt_jumps": self.mean_attempt_jumps,
            "mfpt_jumps": self.mean_attempt_jumps / chance if chance > 0.0 else None,
            "warning": self.warning,
            "seconds": self.seconds,
        }


def effective_size(weights: np.ndarray) -> float:
    """``(sum w)^2 / sum w^2`` (0 without a positive weight), divided through by the largest weight
    first so that the squares cannot overflow."""
    top = float(weights.max()) if weights.size else 0.0
    if top <= 0.0:
        return 0.0
    scaled = weights / top
    return float(scaled.sum() ** 2 / np.square(scaled).sum())


def summarise(climbs: ImportanceClimbs, seconds: float = 0.0) -> PlanImportance:
    """The estimate the ``climbs`` give (:class:`PlanImportance`)."""
    weights = climbs.weights
    weighed = np.where(climbs.failed, weights, 0.0)
    trials, failures = weights.size, int(climbs.failed.sum())
    chance = float(weighed.mean())
    error = float(weighed.std(ddof=1)) / math.sqrt(trials)
    interval = (max(chance - Z95 * error, 0.0), chance + Z95 * error if failures else None)
    ess, effective_failures = effective_size(weights), effective_size(weighed[climbs.failed])
    mean_jumps = float(np.sum(weights * climbs.jumps) / np.sum(weights))
    warning = _warning(trials, failures, ess, effective_failures)
    return PlanImportance(trials, climbs.scale, climbs.scaled, climbs.first_leg_only, failures, chance, error,
                          interval, ess, effective_failures, mean_jumps, warning, seconds)  # fmt: skip


def _warning(trials: int, failures: int, ess: float, effective_failures: float) -> str | None:
    """What makes the interval untrustworthy, said with what to change; None where nothing does."""
    if failures == 0:
        return f"no climb of {trials} failed under the proposal: a larger scale or more climbs"
    if ess < MIN_EFFECTIVE_SHARE * trials:
        return (f"the weights are degenerate (effective sample size {ess:.1f} of {trials} climbs): the scale "
                "is too large for this many widened draws a climb; a smaller scale, or fewer draws widened (fewer "
                "kinds, or touchdown 0's alone)")  # fmt: skip
    if effective_failures < MIN_EFFECTIVE_FAILURES:
        return (f"{effective_failures:.1f} effective failures (under {MIN_EFFECTIVE_FAILURES:g}): a few climbs carry "
                "the estimate and its interval is not to be trusted; more climbs, or widen only the draws that "
                "decide")  # fmt: skip
    return None


def plan_importance(
    model: ModelParams,
    world: World,
    plan: Plan,
    goal: float,
    noise: NoiseModel,
    options: PlanSplitting,
    trials: int,
    first_seed: int,
    scale: float,
    *,
    scaled: tuple[str, ...] = TALLY_KINDS,
    first_leg_only: bool = False,
    settings: PlacementSettings | None = None,
    progress=None,
) -> PlanImportance:
    """The chance that a climb of ``plan`` (followed by the placement law, replanning as ``options``
    allows) fails before a foot at ``goal`` [l0] under ``noise``, by ``trials`` importance-sampled
    climbs (:func:`importance_climbs`: the ``scaled`` kinds' sigmas × ``scale``, at touchdown 0 alone
    where ``first_leg_only``; seeds ``first_seed ..``)."""
    started = time.perf_counter()
    climbs = importance_climbs(model, world, plan, goal, noise, options, trials, first_seed, scale, scaled=scaled,
                               first_leg_only=first_leg_only, settings=settings, progress=progress)  # fmt: skip
    return summarise(climbs, time.perf_counter() - started)
