"""Experiments in the store: one by id (plain or locked for a change), added, deleted, a page of
them with their run counts, and what an experiment still holds (runs, jobs).

A page is one query: each experiment's run count is a correlated count beside its row, read
through the index on ``runs.experiment_id`` (was one count query per listed experiment).
"""

from __future__ import annotations

from sqlalchemy import func, select
from sqlalchemy.orm import Session

from backend.repositories.common import fetch, locked
from backend.store.models import Experiment, Job, Run

_RUN_COUNT = (
    select(func.count(Run.id)).where(Run.experiment_id == Experiment.id).correlate(Experiment).scalar_subquery()
)


def get(session: Session, experiment_id: int) -> Experiment:
    return fetch(session, Experiment, experiment_id, "experiment")


def locked_experiment(session: Session, experiment_id: int) -> Experiment:
    """The experiment, read fresh under the write lock for a change (:func:`~backend.repositories.common.locked`)."""
    return locked(session, Experiment, experiment_id, "experiment")


def add(session: Session, **fields) -> Experiment:
    """A new experiment in the session (the caller commits)."""
    experiment = Experiment(**fields)
    session.add(experiment)
    return experiment


def delete(session: Session, experiment: Experiment) -> None:
    session.delete(experiment)


def run_count(session: Session, experiment_id: int) -> int:
    return session.scalar(select(func.count()).select_from(Run).where(Run.experiment_id == experiment_id)) or 0


def job_count(session: Session, experiment_id: int) -> int:
    return session.scalar(select(func.count()).select_from(Job).where(Job.experiment_id == experiment_id)) or 0


def counted_page(
    session: Session, *, limit: int, cursor: int | None
) -> tuple[list[tuple[Experiment, int]], int | None]:
    """A keyset page of experiments, newest first, each with its run count, and the next cursor
    (None at the end): one query."""
    query = select(Experiment, _RUN_COUNT).order_by(Experiment.id.desc()).limit(limit + 1)
    if cursor is not None:
        query = query.where(Experiment.id < cursor)
    rows = [tuple(row) for row in session.execute(query)]
    if len(rows) > limit:
        return rows[:limit], rows[limit - 1][0].id
    return rows, None


def count(session: Session) -> int:
    """How many experiments there are."""
    return session.scalar(select(func.count()).select_from(Experiment)) or 0
