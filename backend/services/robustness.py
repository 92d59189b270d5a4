"""The robustness study of a calibration: its model's MJTF beside the robot's jumps to failure
(:mod:`experiments.robustness`, docs/calibration.md), from the runs it was fitted to or others.

A robot run failed when its telemetry reported the FELL fault (the firmware's "a jump failed"),
or — without telemetry — when the robot disarmed on its own; a run stopped otherwise (its jumps
done, a stop, a time limit, a lost link) is censored. Its jumps are those between its first and
last touchdown. A replay counts as the robot run it was made from, once. A run in a world is
refused (the model's runs are simulated between parallel walls).
"""

from __future__ import annotations

from collections import defaultdict

from sqlalchemy.orm import Session

from backend.errors import Conflict
from backend.repositories import runs as stored_runs
from backend.services.calibrations import get_stored_preset, preset_params, run_fell, touchdown_series
from backend.store.models import Run
from sim_core.model.errors import ParameterError
from sim_core.model.presets import get_preset

MAX_TRIALS = 5000
MAX_CAP = 100_000


def robustness(
    session: Session, preset: str, run_ids: list[int] | None = None, *, trials: int, cap: int, seed: int = 0
) -> dict:
    """The study's JSON: the preset, the noise it simulates with, and per gait the robot's MJTF and the model's."""
    from experiments.robustness import JumpsToFailure, compare, noise_of
    from sim_core.calibration.touchdown_series import pitch_drift_deg

    if not 1 <= trials <= MAX_TRIALS:
        raise ParameterError("trials", f"must be in [1, {MAX_TRIALS}], got {trials}")
    if not 1 <= cap <= MAX_CAP:
        raise ParameterError("cap", f"must be in [1, {MAX_CAP}], got {cap}")
    stored = get_stored_preset(session, preset)
    robot, offsets = preset_params(session, preset)
    base = get_preset(stored.base)
    tries: dict[tuple, list[tuple[int, bool]]] = defaultdict(list)
    series, seen = [], set()
    for run_id in run_ids or stored.runs:
        run = _robot_run(session, run_id)
        if run.id in seen:
            continue
        seen.add(run.id)
        series.append(touchdown_series(session, run, base))
        tries[_legs(run)].append((run.jumps_completed, run_fell(run)))
    drift = pitch_drift_deg(series)
    noise = noise_of(stored.fit["noise"], drift, offsets)
    groups = {
        legs: JumpsToFailure(tuple(j for j, _ in ends), tuple(f for _, f in ends)) for legs, ends in tries.items()
    }
    rows = compare(groups, robot.to_model(), offsets, noise, trials=trials, cap=cap, seed=seed)
    return {"preset": preset, "runs": sorted(seen), "noise": noise.to_dict(), "trials": trials, "cap": cap,
            "seed": seed, "gaits": rows}  # fmt: skip


def _robot_run(session: Session, run_id: int) -> Run:
    run = stored_runs.get_run(session, run_id)
    if run.kind == "replay":
        run = stored_runs.get_run(session, run.results.get("source_run_id"))
    if run.kind != "robot":
        raise Conflict(f"run {run_id} is a {run.kind} run; the study compares the robot's runs")
    if run.status == "running":
        raise Conflict(f"run {run_id} is still running")
    if run.world_id is not None:  # the model's jumps to failure are simulated between parallel walls
        raise ParameterError("runs", f"run {run_id} climbed world {run.world_id}; the study compares runs between "
                                     "parallel walls")  # fmt: skip
    return run


def _legs(run: Run) -> tuple:
    """The gait commanded: ((psi0_deg, zeta0) left, right); one pair is both legs'."""
    pairs = [tuple(float(v) for v in pair) for pair in run.controls]
    return (pairs[0], pairs[-1])
