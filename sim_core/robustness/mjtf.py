"""Mean Jumps To Failure: Monte-Carlo robustness of a gait under noise (paper Fig. 11, docs/model.md §5).

A trial starts on the gait's fixed point and jumps with the disturbances of
:mod:`sim_core.model.noise` until a jump fails or ``cap`` jumps succeed. Per energy level (zeta0),
``trials`` trials give the mean and standard deviation of the jumps completed, a 95%
confidence interval of the mean, and a histogram of how the trials ended. Capped trials count
as ``cap`` jumps, so with capped trials the mean is a lower bound; the result says how many.

A study is planned once — its levels' starts here (:func:`level_starts`), its trials in chunks in
:mod:`sim_core.robustness.mjtf_plan` (each trial's seed fixed by ``(seed, level, index)``) — and its statistics
computed there once, whether it runs whole (:func:`mjtf_study`) or as a stored job that resumes
with the trials it is missing (``backend.services.job_runner``). The trials themselves are compiled
kernels: :mod:`sim_core.robustness.mjtf_trials`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from sim_core.basins.sweep import energy_sweep, sweep_schedule
from sim_core.chunks import ChunkMap, Progress, in_process
from sim_core.model.controls import LegControl
from sim_core.model.failures import OK, Failure
from sim_core.model.noise import NoiseModel
from sim_core.model.params import ModelParams
from sim_core.model.validation import ParameterError
from sim_core.robustness.mjtf_plan import CAPPED, jump_moments, jump_statistics, no_outcomes, plan_trials
from sim_core.robustness.mjtf_trials import run_trials
from sim_core.robustness.world_trials import run_world_trials
from sim_core.world.world import World

MAX_TRIALS = 1_000_000
MAX_CAP = 1_000_000
DEFAULT_CHUNK_TRIALS = 256


@dataclass(frozen=True)
class MJTFLevel:
    """The trials of one energy level.

    Attributes:
        zeta0: the swept leg length; energy: stored spring energy [m g l0].
        start: the section state trials start from (the gait's fixed point).
        jumps: shape (trials,), jumps completed before the failure (``cap`` if none).
        status: shape (trials,), kernel status of the failing jump, 0 for capped trials.
    """

    zeta0: float
    energy: float
    start: np.ndarray
    jumps: np.ndarray
    status: np.ndarray
    cap: int

    @property
    def mean(self) -> float:
        return jump_statistics(*jump_moments(self.jumps))[0]

    @property
    def std(self) -> float:
        """Sample standard deviation (ddof = 1; 0 for a single trial)."""
        return jump_statistics(*jump_moments(self.jumps))[1]

    @property
    def ci95(self) -> tuple[float, float]:
        """Normal-approximation 95% confidence interval of the mean."""
        half = 1.96 * self.std / math.sqrt(self.jumps.size)
        return self.mean - half, self.mean + half

    def histogram(self) -> dict[str, int]:
        counts = no_outcomes()
        counts[CAPPED] = int(np.count_nonzero(self.status == OK))
        for failure in Failure:
            counts[failure.code] = int(np.count_nonzero(self.status == failure.value))
        return counts

    def to_dict(self) -> dict:
        return {
            "zeta0": self.zeta0,
            "energy": self.energy,
            "start": self.start.tolist(),
            "trials": int(self.jumps.size),
            "mean": self.mean,
            "std": self.std,
            "ci95": list(self.ci95),
            "outcomes": self.histogram(),
            "jumps": self.jumps.tolist(),
        }


@dataclass(frozen=True)
class MJTFStudy:
    psi0: float
    fixed_leg: LegControl | None
    noise: NoiseModel
    trials: int
    cap: int
    seed: int
    levels: tuple[MJTFLevel, ...]
    world: str | None = None  # the world's name, None on the map's parallel walls (docs/model.md §8)
    foot_y: float | None = None  # [l0] touchdown 0's foot in the world

    def to_dict(self) -> dict:
        """The ``parkour mjtf --json`` contract (``world`` and ``foot_y`` only in a world)."""
        in_world = {} if self.world is None else {"world": self.world, "foot_y": self.foot_y}
        return {
            "psi0_deg": round(math.degrees(self.psi0), 9),
            "fixed_leg": None
            if self.fixed_leg is None
            else {"psi0_deg": self.fixed_leg.psi0_deg, "zeta0": self.fixed_leg.zeta0},
            "noise": self.noise.to_dict(),
            "trials": self.trials,
            "cap": self.cap,
            "seed": self.seed,
            "levels": [level.to_dict() for level in self.levels],
        } | in_world


def check_trials(trials: int, cap: int) -> tuple[int, int]:
    for field, value, high in (("trials", trials, MAX_TRIALS), ("cap", cap, MAX_CAP)):
        if isinstance(value, bool) or int(value) != value or not 1 <= value <= high:
            raise ParameterError(field, f"must be an integer in [1, {high:,}], got {value!r}")
    return int(trials), int(cap)


def mjtf_study(
    model: ModelParams,
    psi0: float,
    zeta0s: Sequence[float],
    *,
    noise: NoiseModel,
    trials: int,
    cap: int,
    seed: int = 0,
    fixed_leg: LegControl | None = None,
    guess=None,
    chunk_map: ChunkMap = in_process,
    chunk_trials: int = DEFAULT_CHUNK_TRIALS,
    progress: Progress | None = None,
    world: World | None = None,
    foot_y: float = 0.0,
) -> MJTFStudy:
    """MJTF at each zeta0 (symmetric legs, or one leg fixed as in :func:`sim_core.basins.sweep.energy_sweep`).

    Trials start on each level's fixed point, found by continuation; a level without one
    starts from its neighbour's. Level ``i`` draws its trials' seeds from stream ``i`` of
    ``seed``; the trials run in chunks of ``chunk_trials`` through ``chunk_map``
    (:mod:`sim_core.chunks`), so results do not depend on how the work is split.

    In a ``world`` (docs/model.md §8) each trial climbs from touchdown 0 on the left side, its foot
    at ``foot_y`` [l0], arriving with the level's gait velocity (the gait of parallel walls of
    the model's ``d_hat``), until a jump fails, the body touches down below the floor, or the cap
    (:mod:`sim_core.robustness.world_trials`).
    """
    trials, cap = check_trials(trials, cap)
    levels = level_starts(model, psi0, zeta0s, fixed_leg=fixed_leg, guess=guess)
    chunks = plan_trials(len(levels), trials, seed, chunk_trials)
    arguments = [chunk.arguments(model, levels, noise, cap) for chunk in chunks]
    if world is None:
        results = chunk_map(run_trials, arguments, progress)
    else:
        results = chunk_map(run_world_trials, [(*chunk, world, foot_y) for chunk in arguments], progress)
    out = []
    for index, level in enumerate(levels):
        mine = [result for chunk, result in zip(chunks, results, strict=True) if chunk.level == index]
        jumps = np.concatenate([jumps for jumps, _ in mine])
        status = np.concatenate([status for _, status in mine])
        out.append(MJTFLevel(level.zeta0, level.energy, level.start, jumps, status, cap))
    name = None if world is None else world.name or "unnamed"
    return MJTFStudy(psi0, fixed_leg, noise, trials, cap, int(seed), tuple(out), name,
                     None if world is None else float(foot_y))  # fmt: skip


@dataclass(frozen=True)
class LevelStart:
    """Where one energy level's trials begin: its zeta0, energy, schedule (m, 2) and start state."""

    zeta0: float
    energy: float
    schedule: np.ndarray
    start: np.ndarray


def level_starts(
    model: ModelParams,
    psi0: float,
    zeta0s: Sequence[float],
    *,
    fixed_leg: LegControl | None = None,
    guess=None,
) -> list[LevelStart]:
    """Each level's fixed point by continuation; a level without one starts from its neighbour's."""
    gaits = energy_sweep(model, psi0, zeta0s, fixed_leg=fixed_leg, guess=guess)
    known = [point.gait.state for point in gaits.points if point.gait is not None]
    if not known:
        raise ParameterError("zeta0", "no gait found at any level to start the trials from; give a guess")
    start = known[0]
    levels = []
    for point in gaits.points:
        if point.gait is not None:
            start = point.gait.state
        schedule = sweep_schedule(psi0, point.zeta0, fixed_leg).as_array()
        levels.append(LevelStart(point.zeta0, point.energy, schedule, start.copy()))
    return levels
