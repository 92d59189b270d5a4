"""Experiments: named groups of runs with notes and tags — created, read, edited, deleted, listed
in keyset pages (newest first), each answered as the API's :class:`~backend.schemas.ExperimentOut`
with its run count — and an experiment's page (:func:`summary`: its outcomes, endings and jobs).

An edit or a delete takes the write lock first and reads the experiment fresh under it
(:func:`backend.repositories.common.locked`). Deletes also work on a full disk
(:func:`backend.store.database.freeing_space`): deleting is how space is freed.
"""

from __future__ import annotations

from sqlalchemy.orm import Session

from backend.errors import Conflict
from backend.repositories import experiments as stored
from backend.repositories import jobs as stored_jobs
from backend.repositories import runs as stored_runs
from backend.repositories.runs import RunFilter
from backend.schemas import ExperimentCreate, ExperimentOut, ExperimentPage, ExperimentSummary, ExperimentUpdate
from backend.schemas.experiments import MAX_SUMMARY_JOBS
from backend.services.jobs import public as job_out
from backend.services.runs import aggregate
from backend.store.database import freeing_space
from backend.store.models import Experiment


def create(session: Session, body: ExperimentCreate) -> ExperimentOut:
    experiment = stored.add(session, **body.model_dump())
    session.commit()
    return experiment_out(experiment, stored.run_count(session, experiment.id))


def get(session: Session, experiment_id: int) -> ExperimentOut:
    return experiment_out(stored.get(session, experiment_id), stored.run_count(session, experiment_id))


def summary(session: Session, experiment_id: int) -> ExperimentSummary:
    """The experiment's page: itself, its runs' outcomes (over all and by kind, with 95% intervals
    of the means, grouped in SQL), how they ended, and its newest jobs."""
    experiment = stored.get(session, experiment_id)
    runs = stored.run_count(session, experiment_id)
    its = RunFilter(experiment_id=experiment_id)
    overall = aggregate(session, its, "experiment_id").groups
    jobs, _next = stored_jobs.newest(
        session, state=None, limit=MAX_SUMMARY_JOBS, cursor=None, experiment_id=experiment_id
    )
    return ExperimentSummary(
        experiment=experiment_out(experiment, runs),
        runs=runs,
        outcomes=overall[0] if overall else None,
        by_kind=aggregate(session, its, "kind").groups,
        statuses=stored_runs.counts_by(session, its, "status"),
        end_reasons=stored_runs.counts_by(session, its, "end_reason"),
        loops=stored_runs.counts_by(session, its, "loop"),
        jobs=[job_out(job) for job in jobs],
        jobs_total=stored_jobs.count(session, state=None, experiment_id=experiment_id),
    )


def update(session: Session, experiment_id: int, body: ExperimentUpdate) -> ExperimentOut:
    """Change the fields ``body`` gives (left out or null: as they are), under the write lock."""
    experiment = stored.locked_experiment(session, experiment_id)
    for field, value in body.model_dump(exclude_unset=True).items():
        if value is not None:
            setattr(experiment, field, value)
    session.commit()
    return experiment_out(experiment, stored.run_count(session, experiment_id))


def delete(session: Session, experiment_id: int) -> None:
    """Delete an experiment that holds no runs and no jobs (a :class:`Conflict` if it does)."""

    def remove() -> None:
        experiment = stored.locked_experiment(session, experiment_id)
        if stored.run_count(session, experiment_id):
            raise Conflict(f"experiment {experiment_id} still has runs; delete them first")
        if stored.job_count(session, experiment_id):
            raise Conflict(f"experiment {experiment_id} has jobs, which are kept as its record; it cannot be deleted")
        stored.delete(session, experiment)
        session.commit()

    freeing_space(session, remove)


def list_page(session: Session, *, limit: int, cursor: int | None) -> ExperimentPage:
    """A page of experiments, newest first, with their run counts (one query), the next cursor and
    how many there are."""
    rows, next_cursor = stored.counted_page(session, limit=limit, cursor=cursor)
    return ExperimentPage(
        items=[experiment_out(experiment, runs) for experiment, runs in rows],
        next_cursor=next_cursor,
        total=stored.count(session),
    )


def experiment_out(experiment: Experiment, runs: int) -> ExperimentOut:
    return ExperimentOut(
        id=experiment.id,
        name=experiment.name,
        description=experiment.description,
        notes=experiment.notes,
        tags=experiment.tags,
        created_at=experiment.created_at,
        updated_at=experiment.updated_at,
        runs=runs,
    )
