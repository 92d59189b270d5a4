"""Experiments and runs: create, read, list with filters and keyset pages, update, delete.

Lists are paged on the server by ``id`` (newest first), with every filtered column indexed,
so a page costs the same at 100 runs or 100,000.
"""

from __future__ import annotations

import datetime
from dataclasses import dataclass

from sqlalchemy import func, select
from sqlalchemy.orm import Session

from backend.schemas import ExperimentCreate, ExperimentUpdate, RunCreate
from backend.services.simulation import simulate_run
from backend.store.models import Experiment, Run, RunTag

MAX_PAGE = 500


class NotFound(LookupError):
    def __init__(self, what: str, identifier: int):
        super().__init__(f"{what} {identifier} does not exist")


class Conflict(RuntimeError):
    """The request contradicts stored data (e.g. deleting an experiment that still has runs)."""


def create_experiment(session: Session, body: ExperimentCreate) -> Experiment:
    experiment = Experiment(**body.model_dump())
    session.add(experiment)
    session.commit()
    return experiment


def get_experiment(session: Session, experiment_id: int) -> Experiment:
    experiment = session.get(Experiment, experiment_id)
    if experiment is None:
        raise NotFound("experiment", experiment_id)
    return experiment


def update_experiment(session: Session, experiment_id: int, body: ExperimentUpdate) -> Experiment:
    experiment = get_experiment(session, experiment_id)
    for field, value in body.model_dump(exclude_unset=True).items():
        if value is not None:
            setattr(experiment, field, value)
    session.commit()
    return experiment


def delete_experiment(session: Session, experiment_id: int) -> None:
    experiment = get_experiment(session, experiment_id)
    if run_count(session, experiment_id):
        raise Conflict(f"experiment {experiment_id} still has runs; delete them first")
    session.delete(experiment)
    session.commit()


def run_count(session: Session, experiment_id: int) -> int:
    return session.scalar(select(func.count()).select_from(Run).where(Run.experiment_id == experiment_id)) or 0


def list_experiments(session: Session, *, limit: int, cursor: int | None) -> tuple[list[Experiment], int | None]:
    query = select(Experiment).order_by(Experiment.id.desc()).limit(limit + 1)
    if cursor is not None:
        query = query.where(Experiment.id < cursor)
    rows = list(session.scalars(query))
    return _page(rows, limit)


def create_run(session: Session, body: RunCreate) -> Run:
    if body.experiment_id is not None:
        get_experiment(session, body.experiment_id)
    fields = simulate_run(body)
    run = Run(experiment_id=body.experiment_id, **fields)
    run.run_tags = [RunTag(tag=tag) for tag in sorted(set(body.tags))]
    session.add(run)
    session.commit()
    return run


def get_run(session: Session, run_id: int) -> Run:
    run = session.get(Run, run_id)
    if run is None:
        raise NotFound("run", run_id)
    return run


def delete_run(session: Session, run_id: int) -> None:
    session.delete(get_run(session, run_id))
    session.commit()


@dataclass(frozen=True)
class RunFilter:
    experiment_id: int | None = None
    kind: str | None = None
    status: str | None = None
    tag: str | None = None
    failure_code: str | None = None
    zeta0_min: float | None = None
    zeta0_max: float | None = None
    psi0_min: float | None = None
    psi0_max: float | None = None
    created_after: datetime.datetime | None = None
    created_before: datetime.datetime | None = None


def list_runs(session: Session, where: RunFilter, *, limit: int, cursor: int | None) -> tuple[list[Run], int | None]:
    """A page of runs, newest first; ``cursor`` is the last id of the previous page."""
    query = select(Run).order_by(Run.id.desc()).limit(limit + 1)
    conditions = [
        (where.experiment_id, lambda v: Run.experiment_id == v),
        (where.kind, lambda v: Run.kind == v),
        (where.status, lambda v: Run.status == v),
        (where.failure_code, lambda v: Run.failure_code == v),
        (where.zeta0_min, lambda v: Run.zeta0 >= v),
        (where.zeta0_max, lambda v: Run.zeta0 <= v),
        (where.psi0_min, lambda v: Run.psi0_deg >= v),
        (where.psi0_max, lambda v: Run.psi0_deg <= v),
        (where.created_after, lambda v: Run.created_at >= v),
        (where.created_before, lambda v: Run.created_at < v),
        (cursor, lambda v: Run.id < v),
    ]
    for value, condition in conditions:
        if value is not None:
            query = query.where(condition(value))
    if where.tag is not None:
        query = query.where(Run.id.in_(select(RunTag.run_id).where(RunTag.tag == where.tag)))
    return _page(list(session.scalars(query)), limit)


def _page(rows: list, limit: int) -> tuple[list, int | None]:
    if len(rows) > limit:
        return rows[:limit], rows[limit - 1].id
    return rows, None
