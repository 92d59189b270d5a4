"""Experiments: named groups of runs with notes and tags."""

from __future__ import annotations

from fastapi import APIRouter

from backend import schemas
from backend.api.deps import AUTHORIZED, Cursor, Db, PageLimit, RecordId
from backend.services import experiments

router = APIRouter(prefix="/api/v1/experiments", tags=["experiments"])


@router.post("", status_code=201, dependencies=AUTHORIZED, response_model=schemas.ExperimentOut)
async def create_experiment(body: schemas.ExperimentCreate, db: Db) -> schemas.ExperimentOut:
    return await db(experiments.create, body)


@router.get("", response_model=schemas.ExperimentPage)
async def list_experiments(db: Db, limit: PageLimit = 50, cursor: Cursor = None) -> schemas.ExperimentPage:
    """Experiments, newest first, each with its run count (one query per page), and their ``total``."""
    return await db(experiments.list_page, limit=limit, cursor=cursor)


@router.get("/{experiment_id}", response_model=schemas.ExperimentOut)
async def get_experiment(experiment_id: RecordId, db: Db) -> schemas.ExperimentOut:
    return await db(experiments.get, experiment_id)


@router.get("/{experiment_id}/summary", response_model=schemas.ExperimentSummary)
async def experiment_summary(experiment_id: RecordId, db: Db) -> schemas.ExperimentSummary:
    """The experiment's page: its notes, its runs' outcomes (mean, std, range and 95% confidence
    interval of climb and jumps completed, over all and by kind), how its runs ended, its jobs."""
    return await db(experiments.summary, experiment_id)


@router.patch("/{experiment_id}", dependencies=AUTHORIZED, response_model=schemas.ExperimentOut)
async def update_experiment(experiment_id: RecordId, body: schemas.ExperimentUpdate, db: Db) -> schemas.ExperimentOut:
    return await db(experiments.update, experiment_id, body)


@router.delete("/{experiment_id}", status_code=204, dependencies=AUTHORIZED)
async def delete_experiment(experiment_id: RecordId, db: Db) -> None:
    await db(experiments.delete, experiment_id)
