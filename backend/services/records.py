"""Experiments and runs: create, read, list with filters and keyset pages, update, delete.

Lists are paged on the server by ``id`` (newest first), with every filtered column indexed,
so a page costs the same at 100 runs or 100,000.

A change that depends on what it reads (an update, a delete, a run added to an experiment) takes
the write lock first and reads the rows fresh under it (:func:`locked`): concurrent edits of one
record serialise, each whole, instead of interleaving their reads and writes. Deletes also work on
a full disk (:func:`backend.store.database.freeing_space`): deleting is how space is freed.
"""

from __future__ import annotations

import dataclasses
import json
import math

from sqlalchemy import Float, Integer, case, cast, func, select
from sqlalchemy.orm import Session
from sqlalchemy.orm.attributes import set_committed_value

from backend.errors import Conflict as Conflict  # re-exported until every caller imports backend.errors
from backend.errors import NotFound as NotFound
from backend.repositories.common import fetch as fetch  # re-exported until every caller imports repositories
from backend.repositories.common import locked as locked
from backend.repositories.common import newest_first as newest_first
from backend.repositories.common import page as page
from backend.schemas import ExperimentCreate, ExperimentUpdate, RunCreate
from backend.services.exports import flat_record
from backend.services.simulation import simulate_run
from backend.store.database import freeing_space
from backend.store.models import Experiment, Job, Run, RunTag
from backend.store.run_record import RunRecord
from backend.store.runs import SORTS as SORTS  # re-exported: the API's query parameters are checked against them
from backend.store.runs import RunFilter, add_run, filtered, listed_page
from sim_core.errors import ParameterError

MAX_PAGE = 500


def create_experiment(session: Session, body: ExperimentCreate) -> Experiment:
    experiment = Experiment(**body.model_dump())
    session.add(experiment)
    session.commit()
    return experiment


def get_experiment(session: Session, experiment_id: int) -> Experiment:
    return fetch(session, Experiment, experiment_id, "experiment")


def update_experiment(session: Session, experiment_id: int, body: ExperimentUpdate) -> Experiment:
    experiment = locked(session, Experiment, experiment_id, "experiment")
    for field, value in body.model_dump(exclude_unset=True).items():
        if value is not None:
            setattr(experiment, field, value)
    session.commit()
    return experiment


def delete_experiment(session: Session, experiment_id: int) -> None:
    def remove() -> None:
        experiment = locked(session, Experiment, experiment_id, "experiment")
        if run_count(session, experiment_id):
            raise Conflict(f"experiment {experiment_id} still has runs; delete them first")
        if session.scalar(select(func.count()).select_from(Job).where(Job.experiment_id == experiment_id)):
            raise Conflict(f"experiment {experiment_id} has jobs, which are kept as its record; it cannot be deleted")
        session.delete(experiment)
        session.commit()

    freeing_space(session, remove)


def run_count(session: Session, experiment_id: int) -> int:
    return session.scalar(select(func.count()).select_from(Run).where(Run.experiment_id == experiment_id)) or 0


def list_experiments(session: Session, *, limit: int, cursor: int | None) -> tuple[list[Experiment], int | None]:
    return page(list(session.scalars(newest_first(Experiment, limit, cursor))), limit)


def create_run(session: Session, body: RunCreate, compute=None) -> Run:
    """Simulate ``body`` — in ``compute``'s workers (a :class:`~backend.services.compute.ComputePool`),
    or here without one — and store it as a run. (The API awaits the simulation instead of holding a
    request thread: it checks what the request names (:func:`check_run_request`), awaits the worker,
    then calls :func:`store_run`.)"""
    check_run_request(session, body)
    # Simulated before the lock is taken: it takes a while.
    record = simulate_run(body) if compute is None else compute.run(simulate_run, body)
    return store_run(session, body, record)


def check_run_request(session: Session, body: RunCreate) -> None:
    """What a run request names exists (its experiment): checked before the simulation is paid for."""
    if body.experiment_id is not None:
        get_experiment(session, body.experiment_id)


def store_run(session: Session, body: RunCreate, record: RunRecord) -> Run:
    """Store ``record``, simulated for ``body``, with the request's experiment and tags."""
    if body.experiment_id is not None:  # still there (a concurrent delete waits for this commit)
        locked(session, Experiment, body.experiment_id, "experiment")
    run = add_run(session, dataclasses.replace(record, tags=tuple(body.tags)), experiment_id=body.experiment_id)
    session.commit()
    # The flush expired has_trajectory (an SQL expression), which the answer reads: it is known,
    # and setting it saves a SELECT of the row just written (a tenth of POST /runs's CPU).
    set_committed_value(run, "has_trajectory", record.trajectory is not None)
    return run


def get_run(session: Session, run_id: int) -> Run:
    return fetch(session, Run, run_id, "run")


def update_run(session: Session, run_id: int, *, tags: list[str] | None = None, notes: str | None = None) -> Run:
    """Relabel a run or rewrite its notes; ``None`` leaves a field as it is. One transaction under
    the write lock: the tags it replaces are the ones stored, not ones a concurrent edit replaced
    since they were read (that race inserted a tag twice, a 500, or kept two edits' tags)."""
    run = locked(session, Run, run_id, "run")
    if tags is not None:
        wanted = set(tags)
        kept = [row for row in run.run_tags if row.tag in wanted]  # the rest are deleted (orphans)
        run.run_tags = kept + [RunTag(tag=tag) for tag in sorted(wanted - {row.tag for row in kept})]
    if notes is not None:
        run.notes = notes
    session.flush()
    # The flush expired ``has_trajectory`` (an SQL expression): read it again inside the transaction,
    # since after the commit a concurrent delete may have removed the row it would be read from.
    session.refresh(run, ["has_trajectory"])
    session.commit()
    return run


def delete_run(session: Session, run_id: int) -> None:
    def remove() -> None:
        session.delete(locked(session, Run, run_id, "run"))
        session.commit()

    freeing_space(session, remove)


def list_runs(
    session: Session, where: RunFilter, *, limit: int, cursor: int | None, sort: str = "-id", offset: int = 0
) -> tuple[list[dict], int | None]:
    """A page of runs as the API lists them, and the cursor or offset of the next (None at the end):
    see :func:`backend.store.runs.listed_page`."""
    return listed_page(session, where, limit=limit, cursor=cursor, sort=sort, offset=offset)


MAX_COMPARE = 50
GROUP_BY = ("zeta0", "psi0_deg", "alpha", "kind", "failure_code", "experiment_id", "tag")
CONTINUOUS = ("zeta0", "psi0_deg", "alpha")  # grouped by exact value (at most MAX_GROUPS) or in bins
MAX_GROUPS = 1000
MAX_BINS = 1000


def compare_runs(session: Session, ids: list[int], *, only_differences: bool) -> dict:
    runs = [flat_record(run, run.tags) for run in (get_run(session, run_id) for run_id in ids)]
    fields = list(dict.fromkeys(key for run in runs for key in run))
    differing = [key for key in fields if len({json.dumps(run.get(key)) for run in runs}) > 1]
    shown = [key for key in fields if key == "id" or not only_differences or key in differing]
    return {
        "fields": shown,
        "differing": differing,
        "runs": [{key: run.get(key) for key in shown} for run in runs],
    }


def aggregate_runs(session: Session, where: RunFilter, by: str, bins: int | None = None) -> list[dict]:
    """Groups with count and mean/std/min/max of climb and jumps completed, computed in SQL; the
    same JSON types on every database (PostgreSQL averages integers as numeric: cast to float).

    A continuous parameter (:data:`CONTINUOUS`) groups by its exact values, at most
    :data:`MAX_GROUPS` of them, or with ``bins`` into that many equal bins between the smallest
    and largest value matching: each group's ``key`` is then its bin's centre, with ``low`` and
    ``high`` its edges (the last bin includes its upper edge)."""
    if bins is not None and by not in CONTINUOUS:
        raise ParameterError("bins", f"bins group a continuous parameter ({', '.join(CONTINUOUS)}), not {by}")
    column = RunTag.tag if by == "tag" else getattr(Run, by)
    key, edges = column, None
    if bins is not None:
        low, high = session.execute(filtered(select(func.min(column), func.max(column)), where)).one()
        if low is None:
            return []
        width = (high - low) / bins or 1.0
        key, edges = case((column >= high, bins - 1), else_=cast((column - low) / width, Integer)), (low, width)
    columns = [key.label("key"), func.count(Run.id).label("runs")]
    for name in ("climb", "jumps_completed"):
        value = getattr(Run, name)
        columns += [
            cast(func.avg(value), Float).label(f"{name}_mean"),
            cast(func.avg(value * value), Float).label(f"{name}_mean_square"),
            cast(func.min(value), Float).label(f"{name}_min"),
            cast(func.max(value), Float).label(f"{name}_max"),
        ]
    query = select(*columns)
    query = query.join(RunTag, RunTag.run_id == Run.id) if by == "tag" else query.select_from(Run)
    query = filtered(query, where).group_by(key).order_by(key)
    if by in CONTINUOUS and bins is None:
        distinct = session.scalar(select(func.count()).select_from(query.subquery()))
        if distinct > MAX_GROUPS:
            raise ParameterError("bins", f"{distinct} distinct {by} values: more than {MAX_GROUPS}; ask for bins")
    groups = []
    for row in session.execute(query).mappings():
        group = {"key": row["key"], "runs": row["runs"]}
        if edges is not None:
            low, width = edges
            group |= {"key": low + (row["key"] + 0.5) * width, "low": low + row["key"] * width,
                      "high": low + (row["key"] + 1) * width}  # fmt: skip
        for name in ("climb", "jumps_completed"):
            mean = row[f"{name}_mean"]
            variance = max(row[f"{name}_mean_square"] - mean * mean, 0.0)
            group[name] = {
                "mean": mean,
                "std": math.sqrt(variance),  # population std over the group
                "min": row[f"{name}_min"],
                "max": row[f"{name}_max"],
            }
        groups.append(group)
    return groups
