"""A study job's computation, by kind: sweep, basin, gait search, control study, MFPT (chain or loop)
and viability — what the job runner hands its worker (:mod:`backend.services.job_runner`).

Module-level and picklable, like the quick calls; the kernels load inside the functions.
"""

from __future__ import annotations

import math

from backend.services.model_requests import model_params, schedule_of
from backend.services.presets import resolve_model
from backend.services.quick_calls import gait_not_found_as_parameter_error
from backend.services.section_jobs import section_study
from backend.workers.progress import report
from sim_core.basins.grid import DEFAULT_BASIN_WINDOW, BasinGrid
from sim_core.model.params import ModelParams


def run_study_here(spec) -> dict:
    """:func:`run_study` in the job worker: its chunks one after the other there (each uses every
    core), progress reported to the service (:func:`backend.workers.progress.report`)."""
    from sim_core.chunks import in_process

    return run_study(spec, in_process, report)


def run_study(spec, chunk_map, progress) -> dict:
    """A sweep, basin, gait-search, control-study, MFPT (chain or loop) or viability job's computation; its JSON."""
    from sim_core.basins.sweep import energy_sweep, zeta0_values
    from sim_core.section.gait_search import search_gaits

    model = model_params(spec.model)
    if spec.kind == "control-study":
        return _control_study(spec, model, chunk_map, progress)
    if spec.kind in ("mfpt", "loop-mfpt", "viability"):
        return section_study(spec, model, progress)
    if spec.kind == "sweep":
        psi0 = math.radians(spec.psi0_deg)
        grid = None if spec.basin_grid == 0 else BasinGrid(*DEFAULT_BASIN_WINDOW, spec.basin_grid)
        guess = None if spec.guess is None else (spec.guess.xdot, spec.guess.ydot)
        sweep = energy_sweep(
            model,
            psi0,
            zeta0_values(spec.zeta0_low, spec.zeta0_high, spec.steps),
            guess=guess,
            basin_grid=grid,
            basin_jumps=spec.basin_jumps,
            basin_jump_limit=spec.basin_jump_limit,
            chunk_map=chunk_map,
            progress=progress,
        )
        return sweep.to_dict()
    schedule = schedule_of(spec.controls)
    if spec.kind == "gaits":
        gaits = search_gaits(model, schedule, spec.period or len(schedule), grid=(spec.grid, spec.grid))
        progress(1, 1)
        return {"gaits": [gait.to_dict() for gait in gaits]}
    # basin
    from experiments.gait_basin import gait_basin

    guess = None if spec.guess is None else (spec.guess.xdot, spec.guess.ydot)
    with gait_not_found_as_parameter_error():
        basin = gait_basin(
            model,
            schedule,
            period=spec.period,
            guess=guess,
            grid=spec.grid,
            max_jumps=spec.jumps,
            tolerance=spec.tolerance,
            jump_limit=spec.jump_limit,
            chunk_map=chunk_map,
            progress=progress,
        )
    return basin.to_dict()


def _control_study(spec, model: ModelParams, chunk_map, progress) -> dict:
    """The benchmark's JSON (``parkour control-study --json``) and what the panel plots of it."""
    from experiments.control_study import Config, run

    leg_length = resolve_model(None, spec.model.preset).robot.leg_length  # a stored preset is resolved already
    config = Config(controllers=tuple(spec.controllers), target_m=spec.target_m, psi0_deg=spec.psi0_deg,
                    start_zeta0=spec.start_zeta0, jumps=spec.jumps, seeds=spec.seeds, seed0=spec.seed0,
                    noise=spec.noise.model())  # fmt: skip
    result = run(model, leg_length, config, chunk_map=chunk_map, progress=progress)
    return {**result.to_dict(), "plots": result.plots()}
