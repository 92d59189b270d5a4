"""An MJTF study's plan and statistics (docs/model.md §5): which trials run together, with which
seeds, and what their jumps to failure add up to.

One home for both, used by the library's study (:func:`sim_core.robustness.mjtf.mjtf_study`) and by the
service's job runner, which resumes a stored study with only the trials it is missing and
summarises its stored trials in the database: it plans with :func:`plan_trials` (``done``: the
trials stored) and turns the database's sums into a mean and a standard deviation with
:func:`jump_statistics`. numpy only, like :mod:`sim_core.model.noise`: the service reads a job's results
without loading the kernels.
"""

from __future__ import annotations

import math
from collections.abc import Collection, Sequence
from dataclasses import dataclass

import numpy as np

from sim_core.model.failures import Failure
from sim_core.model.noise import NoiseModel, trial_seeds
from sim_core.model.params import ModelParams

CAPPED = "capped"  # histogram key of trials that reached the cap


@dataclass(frozen=True)
class TrialChunk:
    """Trials of one level run in one call: their indices in the level and their seeds, shape (n,) each."""

    level: int
    indices: np.ndarray
    seeds: np.ndarray

    def arguments(self, model: ModelParams, levels: Sequence, noise: NoiseModel, cap: int) -> tuple:
        """:func:`sim_core.robustness.mjtf_trials.run_trials`' arguments for this chunk; ``levels``: the study's
        :class:`~sim_core.robustness.mjtf.LevelStart` (schedule and start state of each)."""
        start = levels[self.level]
        return model, start.schedule, start.start, noise, self.seeds, cap


def plan_trials(
    levels: int, trials: int, seed: int, chunk_trials: int, done: Sequence[Collection[int]] | None = None
) -> list[TrialChunk]:
    """A study's trials in chunks of at most ``chunk_trials``, level by level and index by index,
    leaving out those in ``done[level]`` (a resumed study's stored trials). Trial ``i`` of level
    ``l`` has seed ``trial_seeds(seed, l, trials)[i]``, however the trials are split or resumed."""
    if chunk_trials < 1:
        raise ValueError(f"chunk size must be >= 1, got {chunk_trials}")
    chunks = []
    for level in range(levels):
        seeds = trial_seeds(seed, level, trials)
        missing = np.arange(trials, dtype=np.int64)
        if done is not None and done[level]:
            missing = np.setdiff1d(missing, np.fromiter(done[level], dtype=np.int64))
        for first in range(0, missing.size, chunk_trials):
            indices = missing[first : first + chunk_trials]
            chunks.append(TrialChunk(level, indices, seeds[indices]))
    return chunks


def no_outcomes() -> dict[str, int]:
    """A level's outcome histogram before any trial: capped and each failure, all 0, in report order."""
    return {CAPPED: 0} | {failure.code: 0 for failure in Failure}


def jump_statistics(trials: int, total: int, squares: int) -> tuple[float, float]:
    """``(mean, sample std)`` of jumps to failure from their moments: the number of ``trials``,
    the ``total`` of their jumps and the sum of its ``squares`` (exact integers, so the variance's
    numerator is exact: summed by the database for a stored job, by numpy here). The mean of no
    trials is NaN; the std of fewer than two is 0."""
    variance = (trials * squares - total * total) / (trials * (trials - 1)) if trials > 1 else 0.0
    return (total / trials if trials else math.nan), math.sqrt(max(variance, 0.0))


def jump_moments(jumps: np.ndarray) -> tuple[int, int, int]:
    """``(trials, total, squares)`` of the jumps of some trials, shape (trials,): :func:`jump_statistics`' arguments."""
    jumps = jumps.astype(np.int64, copy=False)  # cap and trials at most 1e6 each: the squares fit in int64
    return int(jumps.size), int(jumps.sum()), int(np.dot(jumps, jumps))
