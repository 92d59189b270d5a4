"""Runs: simulated and stored, read, relabelled, deleted, listed with filters and pages, compared,
grouped, and their paths read back. Each function is one unit of work on the session it is given
and answers with the schema the API returns.

Lists are paged on the server by ``id`` (newest first), with every filtered column indexed,
so a page costs the same at 100 runs or 100,000 (:mod:`backend.repositories.runs`).

A change that depends on what it reads (an update, a delete, a run added to an experiment) takes
the write lock first and reads the rows fresh under it
(:func:`backend.repositories.common.locked`): concurrent edits of one record serialise, each
whole, instead of interleaving their reads and writes. Deletes also work on a full disk
(:func:`backend.store.database.freeing_space`): deleting is how space is freed.
"""

from __future__ import annotations

import dataclasses
import json

from sqlalchemy.orm import Session

from backend.errors import NotFound
from backend.repositories import experiments as stored_experiments
from backend.repositories import runs as stored_runs
from backend.repositories import worlds as stored_worlds
from backend.repositories.runs import RunFilter
from backend.schemas import RunAggregate, RunComparison, RunCreate, RunDetail, RunOut, RunTrajectory
from backend.services.exports import flat_record
from backend.services.presets import InSession, preset_resolved
from backend.services.quick_calls import simulate_run
from backend.services.run_stats import stats
from backend.services.worlds import world_in_l0
from backend.store.database import freeing_space
from backend.store.models import Run
from backend.store.run_record import RunRecord
from backend.store.trajectory_blob import unpack_trajectory
from sim_core.model.errors import ParameterError

SORTS = stored_runs.SORTS  # the API's sort parameter is checked against them
MAX_COMPARE = 50
GROUP_BY = ("zeta0", "psi0_deg", "alpha", "kind", "failure_code", "experiment_id", "tag", "status", "end_reason",
            "loop", "controller", "target")  # fmt: skip
CONTINUOUS = ("zeta0", "psi0_deg", "alpha", "target")  # grouped by exact value (at most MAX_GROUPS) or in bins
MAX_GROUPS = 1000
MAX_BINS = 1000
# A simulated run's path is nondimensional (docs/model.md §1); a robot or replay run's is the tracker's frames.
SIMULATED_UNITS = {"time": "sqrt(l0/g)", "x": "l0", "y": "l0", "foot_x": "l0", "foot_y": "l0", "psi": "rad",
                   "zeta": "l0", "phase": "0 stance, 1 flight", "jump": "index"}  # fmt: skip
RECORDED_UNITS = {"time": "s", "x": "m", "y": "m", "pitch": "rad"}


async def create(in_session: InSession, compute, body: RunCreate, *, person: str | None = None) -> RunDetail:
    """Simulate ``body`` in ``compute``'s quick worker (a :class:`~backend.workers.pools.ComputePool`)
    and store it: the model it names resolved, the experiment it names checked before the
    simulation is paid for, the simulation awaited (no request thread waits for it), the run stored
    in a request thread."""
    body = await preset_resolved(in_session, body)
    world = None
    if body.experiment_id is not None or body.world_id is not None:
        world = await in_session(check_run_request, body)
    record = await compute.call(simulate_run, body, world)
    return await in_session(store_run, body, record, person=person)


def create_run(session: Session, body: RunCreate, compute=None, *, person: str | None = None) -> RunDetail:
    """:func:`create` without an event loop: simulated in ``compute``'s workers or, without one, here."""
    world = check_run_request(session, body)
    # Simulated before the lock is taken: it takes a while.
    record = simulate_run(body, world) if compute is None else compute.run(simulate_run, body, world)
    return store_run(session, body, record, person=person)


def check_run_request(session: Session, body: RunCreate) -> dict | None:
    """What a run request names exists (its experiment, its world): checked before the simulation is
    paid for. Returns the world's §8 JSON in ``l0`` (metres read with the model preset's leg length),
    or None for parallel walls."""
    if body.experiment_id is not None:
        stored_experiments.get(session, body.experiment_id)
    if body.world_id is None:
        return None
    return world_in_l0(session, body.world_id, body.model.preset)


def store_run(session: Session, body: RunCreate, record: RunRecord, *, person: str | None = None) -> RunDetail:
    """Store ``record``, simulated for ``body`` asked by ``person``, with the request's experiment and tags."""
    if body.experiment_id is not None:  # still there (a concurrent delete waits for this commit)
        stored_experiments.locked_experiment(session, body.experiment_id)
    if body.world_id is not None:  # the same for its world
        stored_worlds.locked(session, body.world_id)
    record = dataclasses.replace(record, tags=tuple(body.tags), world_id=body.world_id)
    run = stored_runs.add_run(session, record, experiment_id=body.experiment_id, created_by=person)
    session.commit()
    stored_runs.stored_has_trajectory(run, record.trajectory is not None)
    return run_detail(run)


def get(session: Session, run_id: int) -> RunDetail:
    return run_detail(stored_runs.get_run(session, run_id))


def update(
    session: Session, run_id: int, *, tags: list[str] | None = None, notes: str | None = None, person: str | None = None
) -> RunOut:
    """Relabel a run or rewrite its notes, as ``person`` (kept as ``notes_by``); ``None`` leaves a
    field as it is. One transaction under
    the write lock: the tags it replaces are the ones stored, not ones a concurrent edit replaced
    since they were read (that race inserted a tag twice, a 500, or kept two edits' tags)."""
    run = stored_runs.locked_run(session, run_id)
    if tags is not None:
        stored_runs.relabel(run, tags)
    if notes is not None:
        run.notes = notes
    if tags is not None or notes is not None:
        run.notes_by = person
    stored_runs.flushed(session, run)
    session.commit()
    return run_out(run)


def delete(session: Session, run_id: int) -> None:
    def remove() -> None:
        session.delete(stored_runs.locked_run(session, run_id))
        session.commit()

    freeing_space(session, remove)


def list_runs(
    session: Session, where: RunFilter, *, limit: int, cursor: int | None, sort: str = "-id", offset: int = 0
) -> tuple[list[dict], int | None, int]:
    """A page of runs as the API lists them, the cursor or offset of the next (None at the end) and
    how many match in all: see :func:`backend.repositories.runs.listed_page`. Run in the read
    workers (backend/workers)."""
    return stored_runs.listed_page(session, where, limit=limit, cursor=cursor, sort=sort, offset=offset)


def trajectory_json(session: Session, run_id: int) -> bytes:
    """The run's sampled path as :class:`~backend.schemas.RunTrajectory` JSON, column by column."""
    run = stored_runs.get_run(session, run_id)
    if run.trajectory is None:
        raise NotFound("trajectory of run", run_id)
    columns = unpack_trajectory(run.trajectory)
    listed = {name: values.tolist() for name, values in columns.items()}
    units, table = ("nondimensional", SIMULATED_UNITS) if run.kind == "sim" else ("SI", RECORDED_UNITS)
    column_units = {name: table.get(name, "") for name in listed}
    return RunTrajectory(units=units, column_units=column_units, columns=listed).model_dump_json().encode()


def compare(session: Session, ids: list[int], *, only_differences: bool) -> RunComparison:
    runs = [flat_record(run, run.tags) for run in (stored_runs.get_run(session, run_id) for run_id in ids)]
    fields = list(dict.fromkeys(key for run in runs for key in run))
    differing = [key for key in fields if len({json.dumps(run.get(key)) for run in runs}) > 1]
    shown = [key for key in fields if key == "id" or not only_differences or key in differing]
    return RunComparison.model_validate(
        {"fields": shown, "differing": differing, "runs": [{key: run.get(key) for key in shown} for run in runs]}
    )


def aggregate(session: Session, where: RunFilter, by: str, bins: int | None = None) -> RunAggregate:
    """Groups with count and mean/std/min/max of climb and jumps completed, computed in SQL, and the
    95% confidence interval of each mean (:mod:`backend.services.run_stats`); the same JSON types
    on every database.

    A continuous parameter (:data:`CONTINUOUS`) groups by its exact values, at most
    :data:`MAX_GROUPS` of them, or with ``bins`` into that many equal bins between the smallest
    and largest value matching: each group's ``key`` is then its bin's centre, with ``low`` and
    ``high`` its edges (the last bin includes its upper edge)."""
    return RunAggregate.model_validate({"by": by, "bins": bins, "groups": _groups(session, where, by, bins)})


def _groups(session: Session, where: RunFilter, by: str, bins: int | None) -> list[dict]:
    if bins is not None and by not in CONTINUOUS:
        raise ParameterError("bins", f"bins group a continuous parameter ({', '.join(CONTINUOUS)}), not {by}")
    edges = None
    if bins is not None:
        low, high = stored_runs.value_range(session, where, by)
        if low is None:
            return []
        width = (high - low) / bins or 1.0
        edges = (low, high, width, bins)
    elif by in CONTINUOUS:
        distinct = stored_runs.group_count(session, where, by)
        if distinct > MAX_GROUPS:
            raise ParameterError("bins", f"{distinct} distinct {by} values: more than {MAX_GROUPS}; ask for bins")
    groups = []
    for row in stored_runs.group_stats(session, where, by, edges):
        group = {"key": row["key"], "runs": row["runs"]}
        if edges is not None:
            low, _, width, _ = edges
            group |= {"key": low + (row["key"] + 0.5) * width, "low": low + row["key"] * width,
                      "high": low + (row["key"] + 1) * width}  # fmt: skip
        for name in ("climb", "jumps_completed"):
            group[name] = stats(
                row["runs"], row[f"{name}_mean"], row[f"{name}_mean_square"], row[f"{name}_min"], row[f"{name}_max"]
            )
        groups.append(group)
    return groups


def run_out(run: Run) -> RunOut:
    """A stored run as listed (everything but its results and path)."""
    return RunOut.model_validate(_fields(run))


def run_detail(run: Run) -> RunDetail:
    """A stored run in full, with its results."""
    return RunDetail.model_validate({**_fields(run), "results": run.results})


def _fields(run: Run) -> dict:
    return {
        "id": run.id,
        "experiment_id": run.experiment_id,
        "world_id": run.world_id,
        "kind": run.kind,
        "status": run.status,
        "created_at": run.created_at,
        "duration_s": run.duration_s,
        "code_version": run.code_version,
        "model": run.model,
        "controls": run.controls,
        "start_state": run.start_state,
        "jumps": run.jumps,
        "jumps_completed": run.jumps_completed,
        "failure_code": run.failure_code,
        "climb": run.climb,
        "tags": run.tags,
        "notes": run.notes,
        "has_trajectory": run.has_trajectory,
        "end_reason": run.end_reason,
        "loop": run.loop,
        "controller": run.controller,
        "target": run.target,
        "touchdowns": run.touchdowns,
        "created_by": run.created_by,
        "notes_by": run.notes_by,
    }
