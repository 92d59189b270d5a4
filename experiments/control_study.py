"""The closed-loop benchmark as one study: which controllers, on what climb and noise, and what the
command line, the job and the panel show of it.

``parkour control-study`` and the service's ``control-study`` job both call :func:`run`; the laws
are built here once (:func:`laws_for`): the PIDs about the in-place zeta0 of Fig. 12's loop, the
LQR designed on the model's own return map (:func:`sim_core.control.return_map_lqr.design_lqr`), so a
calibrated preset gets its own.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from experiments.fig12 import Config as ClimbConfig
from experiments.fig12 import PidClimb
from sim_core.chunks import ChunkMap, Progress, in_process
from sim_core.climb.records import CHUTE_TOP, FLOOR
from sim_core.control.design import design_law
from sim_core.control.laws import Controller
from sim_core.control.registry import NAMES, check_names
from sim_core.control.study import ControllerOutcome, control_study
from sim_core.model.noise import NoiseModel
from sim_core.model.params import ModelParams
from sim_core.model.validation import check_range

FAILURE_CURVE_POINTS = 41  # failures counted at this many jumps, 0 .. jumps
ERROR_BINS = 40  # the height error's histogram, over ±ERROR_SPAN_M
ERROR_SPAN_M = 0.05


def check_controllers(names) -> tuple[str, ...]:
    """``names`` in order, each a registered controller once; a ParameterError naming ``controllers``."""
    return check_names(names, "controllers")


@dataclass(frozen=True)
class Config:
    """The study: ``controllers`` by name, the height to hold [m], the climb's nominal leg angle
    [deg] and starting zeta0, and the trials (seeds ``seed0 .. seed0 + seeds - 1``)."""

    controllers: tuple[str, ...] = NAMES
    target_m: float = 0.55
    psi0_deg: float = 35.0
    start_zeta0: float = 0.9
    jumps: int = 400
    seeds: int = 200
    seed0: int = 0
    noise: NoiseModel = field(default_factory=NoiseModel)


@dataclass(frozen=True)
class Result:
    config: Config
    leg_length: float  # [m]
    outcomes: tuple[ControllerOutcome, ...]

    def to_dict(self) -> dict:
        """``parkour control-study --json`` (issue 27's contract)."""
        config = self.config
        return {
            "target_m": config.target_m,
            "jumps": config.jumps,
            "seeds": [config.seed0, config.seeds],
            "noise": config.noise.to_dict(),
            "controllers": [outcome.to_dict(self.leg_length) for outcome in self.outcomes],
        }

    def plots(self) -> dict:
        """What the panel draws, per controller: failures by jump (``failure_curve``: the trials
        failed within ``jumps`` jumps), the height error's histogram once risen [m], and the first
        trials' climbs (touchdown heights [m])."""
        jumps = self.config.jumps
        at = np.unique(np.linspace(0, jumps, FAILURE_CURVE_POINTS).round().astype(int))
        edges = np.linspace(-ERROR_SPAN_M, ERROR_SPAN_M, ERROR_BINS + 1)
        controllers = []
        for outcome in self.outcomes:
            failed = np.sort(outcome.failure_jumps)
            errors = np.clip(outcome.height_errors * self.leg_length, -ERROR_SPAN_M, ERROR_SPAN_M)
            counts, _ = np.histogram(errors, edges)
            controllers.append({
                "name": outcome.name,
                "failure_curve": {"jumps": at.tolist(), "failures": np.searchsorted(failed, at, "right").tolist()},
                "height_error_histogram": {"edges_m": edges.tolist(), "counts": counts.tolist()},
                "examples": [(example * self.leg_length).tolist() for example in outcome.examples],
            })  # fmt: skip
        return {"target_m": self.config.target_m, "controllers": controllers}


def laws_for(model: ModelParams, config: Config, leg_length: float) -> tuple[PidClimb, list[Controller]]:
    """The climb (its start, its PID) and each named law for it; ``leg_length`` [m] converts the
    target. Checked first: a ParameterError naming the field."""
    names = check_controllers(config.controllers)
    check_range("target", config.target_m, FLOOR, CHUTE_TOP, high_open=False)
    climb = ClimbConfig(target_m=config.target_m, psi0_deg=config.psi0_deg, start_zeta0=config.start_zeta0,
                        jumps=config.jumps)  # fmt: skip
    loop = PidClimb.of(model, climb, leg_length)
    laws = [design_law(name, model, loop.controller, config.psi0_deg) for name in names]
    return loop, laws


def run(
    model: ModelParams,
    leg_length: float,
    config: Config,
    *,
    chunk_map: ChunkMap = in_process,
    progress: Progress | None = None,
) -> Result:
    """Every controller of ``config`` on the same noise draws (:func:`sim_core.control.study.control_study`)."""
    loop, laws = laws_for(model, config, leg_length)
    outcomes = control_study(model, laws, loop.start, config.start_zeta0, config.jumps, config.seed0, config.seeds,
                             config.noise, chunk_map=chunk_map, progress=progress)  # fmt: skip
    return Result(config, leg_length, tuple(outcomes))
