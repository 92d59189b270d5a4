"""Calibrations: the model fitted to stored robot runs, kept as a named preset (docs/calibration.md).

:func:`calibrate_runs` reads the touchdowns of robot and replay runs (each touchdown's measured
section state and foot height, the controls commanded for it, the body's pitch from the tracker
frames just after it), fits the model (:func:`sim_core.calibration.calibrate.calibrate`) and stores the
result as a :class:`~backend.store.models.ModelPreset` with its provenance: the runs, the date and
the code version. A stored preset is used by name wherever a built-in one is
(:func:`backend.services.presets.resolve_model`): the CLI's ``--preset``, the API's ``model.preset``.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from dataclasses import asdict

import numpy as np
from sqlalchemy.orm import Session

from backend.errors import Conflict
from backend.repositories import calibrations as stored_presets
from backend.repositories import runs as stored_runs
from backend.repositories import worlds as stored_worlds
from backend.robot.run_endings import robot_ending_record
from backend.schemas.calibrations import (
    PRESET_PATTERN,
    CalibrationCreate,
    CalibrationList,
    CalibrationOut,
    TouchdownComparison,
)
from backend.services.presets import resolve_model
from backend.services.provenance import current_code_version
from backend.store.models import ModelPreset, Run
from backend.store.trajectory_blob import unpack_trajectory
from experiments.manifest import json_safe
from sim_core.calibration.fit import CalibrationFit
from sim_core.calibration.touchdown_series import TouchdownSeries, finite_rms, pitch_at
from sim_core.model.controls import NO_OFFSETS, LegControl, LegOffsets
from sim_core.model.errors import ParameterError
from sim_core.model.params import ModelParams, PhysicalParams
from sim_core.model.presets import PRESETS, get_preset
from sim_core.model.walls import Wall
from sim_core.world.files import world_from_document
from sim_core.world.world import World as SimWorld

CALIBRATED_KINDS = ("robot", "replay")
PRESET_NAME = re.compile(PRESET_PATTERN)
MAX_RUNS = 100
Fitter = Callable[[list[TouchdownSeries], ModelParams], CalibrationFit]


def check_preset_name(name: str) -> str:
    if not PRESET_NAME.match(name):
        raise ParameterError(
            "name", f"must be 1 to 64 letters, digits, '_', '.' or '-', starting with a letter or digit; got {name!r}"
        )
    if name in PRESETS:
        raise ParameterError("name", f"{name!r} is a built-in preset; choose another name")
    return name


def touchdown_series(session: Session, run: Run, robot: PhysicalParams) -> TouchdownSeries:
    """A stored run's touchdowns as the fit reads them (heights in l0, controls in radians)."""
    touchdowns = run.results.get("touchdowns") or []
    controls = _touchdown_controls(session, run)
    if len(controls) < len(touchdowns):
        raise Conflict(
            f"run {run.id} does not say which controls {len(touchdowns) - len(controls)} of its touchdowns had"
        )
    legs = [LegControl.from_degrees(*pair) for pair in controls[: len(touchdowns)]]
    tracked = _tracked(session, run)
    return TouchdownSeries.of(
        state=[td["state"] for td in touchdowns],
        foot_height=[td["foot_height"] / robot.leg_length for td in touchdowns],
        commanded=[(leg.psi0, leg.zeta0) for leg in legs],
        right_leg=[td["wall"] == Wall.RIGHT for td in touchdowns],
        pitch=_pitch_at(tracked, [td["time"] for td in touchdowns]),
        fell=tracked is not None and run_fell(tracked),
    )


def run_fell(run: Run) -> bool:
    """Whether a robot run ended in a fall, as it was stored: its record says so (``fell``, from its
    end reason and the robot's faults), or, stored before that record, its telemetry carried the
    firmware's FELL fault or it ended as a robot that disarmed itself did."""
    results = run.results
    if "fell" in results:
        return bool(results["fell"])
    return robot_ending_record(results.get("end_reason"), (), results.get("telemetry") or [])["fell"]


def fit_touchdowns(series: list[TouchdownSeries], base: ModelParams) -> CalibrationFit:
    """:func:`sim_core.calibration.calibrate.calibrate`, loaded where it runs (a compute worker, a command)."""
    from sim_core.calibration.calibrate import calibrate

    return calibrate(series, base)


def predict_touchdowns(series: TouchdownSeries, models: dict, world: SimWorld | None = None) -> dict:
    """:func:`sim_core.calibration.calibrate.one_jump_predictions` between parallel walls, or in
    ``world`` (a run that climbed one, in ``l0``)
    :func:`sim_core.calibration.world_jumps.world_one_jump_predictions`; loaded where it runs."""
    if world is not None:
        from sim_core.calibration.world_jumps import world_one_jump_predictions

        return world_one_jump_predictions(series, models, world)
    from sim_core.calibration.calibrate import one_jump_predictions

    return one_jump_predictions(series, models)


def calibrate_runs(
    session: Session, run_ids: list[int], *, name: str, base: str = "paper", fit: Fitter = fit_touchdowns
) -> dict:
    """Fit the model to ``run_ids`` and store it as preset ``name``; the ``parkour calibrate --json`` payload.

    ``fit`` is :func:`fit_touchdowns` or a call of it elsewhere (the service's compute worker): it
    gets the runs' :class:`TouchdownSeries` and the base model, nothing of the store.
    """
    check_preset_name(name)
    if not 1 <= len(run_ids) <= MAX_RUNS:
        raise ParameterError("runs", f"give 1 to {MAX_RUNS} run ids, got {len(run_ids)}")
    if stored_presets.exists(session, name):
        raise Conflict(f"a preset named {name!r} exists; choose another name or delete it")
    robot = get_preset(base)
    series = [touchdown_series(session, _between_walls(_calibration_run(session, run_id)), robot) for run_id in run_ids]
    session.rollback()  # no read transaction held open while the fit runs
    fitted = fit(series, robot.to_model())
    preset = _stored(fitted, name=name, base=base, robot=robot, run_ids=run_ids)
    stored_presets.add(session, preset)  # a Conflict if stored by someone else meanwhile
    session.commit()
    return preset_payload(preset)


def create(session: Session, body: CalibrationCreate, *, fit: Fitter = fit_touchdowns) -> CalibrationOut:
    """:func:`calibrate_runs` for the API's request, answered as the API gives a calibration."""
    return CalibrationOut.model_validate(calibrate_runs(session, body.runs, name=body.name, base=body.preset, fit=fit))


def preset_payload(preset: ModelPreset) -> dict:
    """A stored calibration as the CLI and the API give it: the fit's report and the preset's provenance."""
    return json_safe(
        {
            **preset.fit,
            "preset": {
                "name": preset.name,
                "base": preset.base,
                "runs": list(preset.runs),
                "created_at": preset.created_at.isoformat(),
                "code_version": preset.code_version,
                "physical": preset.physical,
            },
        }
    )


def list_calibrations(session: Session) -> CalibrationList:
    """Every stored calibration's :func:`preset_payload`, oldest first."""
    return CalibrationList.model_validate(
        {"items": [preset_payload(preset) for preset in stored_presets.all_presets(session)]}
    )


def get_calibration(session: Session, name: str) -> CalibrationOut:
    return CalibrationOut.model_validate(preset_payload(stored_presets.get(session, name)))


def list_presets(session: Session) -> list[ModelPreset]:
    """Every stored preset, oldest first (the 3D view offers them as ghosts)."""
    return stored_presets.all_presets(session)


def get_stored_preset(session: Session, name: str) -> ModelPreset:
    return stored_presets.get(session, name)


def delete_preset(session: Session, name: str) -> None:
    stored_presets.delete(session, name)
    session.commit()


def preset_params(session: Session | None, name: str) -> tuple[PhysicalParams, LegOffsets]:
    """The robot and leg offsets of preset ``name``: a built-in one, else one stored in ``session``'s
    database; a :class:`ParameterError` naming the known presets if neither has it."""
    resolved = resolve_model(session, name)
    return resolved.robot, resolved.offsets


def _stored(fit: CalibrationFit, *, name: str, base: str, robot: PhysicalParams, run_ids: list[int]) -> ModelPreset:
    fitted = PhysicalParams.from_model(fit.model, mass=robot.mass, leg_length=robot.leg_length, gravity=robot.gravity)
    return ModelPreset(
        name=name,
        base=base,
        physical=json_safe(asdict(fitted)),
        offsets=fit.offsets.to_dict(),
        fit=json_safe(_with_run_ids(fit.to_dict(), run_ids)),
        runs=list(run_ids),
        code_version=current_code_version(),
    )


def _with_run_ids(report: dict, run_ids: list[int]) -> dict:
    """The fit's report with each outlier and each cut at a fall naming its run (``run_id``) beside
    its position in the runs (``series``)."""
    for key in ("outliers", "cut_at_fall"):
        report[key] = [{**entry, "run_id": run_ids[entry["series"]]} for entry in report.get(key, [])]
    return report


def _calibration_run(session: Session, run_id: int) -> Run:
    run = stored_runs.get_run(session, run_id)
    if run.kind not in CALIBRATED_KINDS:
        raise Conflict(f"run {run_id} is a {run.kind} run; calibration fits robot and replay runs")
    if run.status == "running":
        raise Conflict(f"run {run_id} is still running; calibrate once it has ended")
    return run


def _between_walls(run: Run) -> Run:
    """``run``, if it climbed the parallel walls the fit's map assumes; a run in a world is refused."""
    if run.world_id is not None:
        raise ParameterError(
            "runs", f"run {run.id} climbed world {run.world_id}; calibration fits runs between parallel walls"
        )
    return run


def _tracked(session: Session, run: Run) -> Run | None:
    """The robot run whose tracker frames and commands ``run`` has: itself, or a replay's source."""
    if run.kind == "replay":
        return stored_runs.find(session, run.results.get("source_run_id"))
    return run


def _touchdown_controls(session: Session, run: Run) -> list:
    """The controls commanded for each touchdown: stored with the run (robot runs, replays since
    calibration came) or with the robot run an older replay was made from."""
    controls = run.results.get("touchdown_controls")
    if controls is None:
        source = _tracked(session, run)
        controls = None if source is None else source.results.get("touchdown_controls")
    return controls or []


def _pitch_at(run: Run | None, times: list[float]) -> np.ndarray:
    """The tracked pitch [rad] at each touchdown (:func:`sim_core.calibration.touchdown_model.pitch_at`);
    0 without frames."""
    frames = None if run is None or run.trajectory is None else unpack_trajectory(run.trajectory)
    if frames is None or "pitch" not in frames:
        return np.zeros(len(times))
    return pitch_at(times, frames["time"], frames["pitch"])


def touchdown_predictions(session: Session, run_id: int, *, preset: str | None, predict=None) -> TouchdownComparison:
    """A robot or replay run's touchdowns as measured, as the base model predicts each from the one
    before, and (``preset``, a stored calibration) as the calibrated model does, with the residuals
    and their RMS; a run in a world is predicted by each model's jump in that world (``world``: its
    id and name; None: between parallel walls). ``predict`` is :func:`predict_touchdowns` or a call
    of it in a compute worker."""
    run = _calibration_run(session, run_id)
    stored = None if preset is None else get_stored_preset(session, preset)
    base_name = stored.base if stored is not None else "paper"
    base = get_preset(base_name)
    series = touchdown_series(session, run, base)
    models = {"paper": (base.to_model(), NO_OFFSETS)}
    if stored is not None:
        robot, offsets = preset_params(session, preset)
        models["calibrated"] = (robot.to_model(), offsets)
    world = None if run.world_id is None else stored_worlds.get(session, run.world_id)
    chute = None if world is None else world_from_document(world.document, base.leg_length)  # a world in m needs l0
    named = None if world is None else {"id": world.id, "name": world.name}
    session.rollback()
    found = (predict or predict_touchdowns)(series, models, chute)
    touchdowns = run.results.get("touchdowns") or []
    rows = []
    for row, k in enumerate(found["index"]):
        entry = {"index": k, "time": touchdowns[k]["time"], "wall": Wall(touchdowns[k]["wall"]).code,
                 "measured": _channels(found["measured"][row])}  # fmt: skip
        for name in models:
            predicted = found[name][row]
            entry[name] = _channels(predicted)
            entry[f"{name}_residual"] = _channels(predicted - found["measured"][row])
        rows.append(entry)
    rms = {name: _channels(finite_rms(found[name] - found["measured"], axis=0)) for name in models}
    return TouchdownComparison.model_validate(
        json_safe(
            {"run_id": run_id, "base": base_name, "preset": preset, "world": named, "touchdowns": rows, "rms": rms}
        )
    )


def _channels(values) -> dict:
    return dict(zip(("xdot", "ydot", "rise"), (float(v) for v in values), strict=True))
