"""Experiments: named groups of runs with notes and tags."""

from __future__ import annotations

from fastapi import APIRouter
from sqlalchemy.orm import Session

from backend import schemas
from backend.api.deps import AUTHORIZED, Cursor, Db, PageLimit, RecordId
from backend.services import records

router = APIRouter(prefix="/api/v1/experiments", tags=["experiments"])


@router.post("", status_code=201, dependencies=AUTHORIZED, response_model=schemas.ExperimentOut)
async def create_experiment(body: schemas.ExperimentCreate, db: Db):
    return await db(lambda session: experiment_out(session, records.create_experiment(session, body)))


@router.get("", response_model=schemas.ExperimentPage)
async def list_experiments(db: Db, limit: PageLimit = 50, cursor: Cursor = None):
    def page(session: Session) -> dict:
        rows, next_cursor = records.list_experiments(session, limit=limit, cursor=cursor)
        return {"items": [experiment_out(session, row) for row in rows], "next_cursor": next_cursor}

    return await db(page)


@router.get("/{experiment_id}", response_model=schemas.ExperimentOut)
async def get_experiment(experiment_id: RecordId, db: Db):
    return await db(lambda session: experiment_out(session, records.get_experiment(session, experiment_id)))


@router.patch("/{experiment_id}", dependencies=AUTHORIZED, response_model=schemas.ExperimentOut)
async def update_experiment(experiment_id: RecordId, body: schemas.ExperimentUpdate, db: Db):
    return await db(lambda session: experiment_out(session, records.update_experiment(session, experiment_id, body)))


@router.delete("/{experiment_id}", status_code=204, dependencies=AUTHORIZED)
async def delete_experiment(experiment_id: RecordId, db: Db) -> None:
    await db(records.delete_experiment, experiment_id)


def experiment_out(session: Session, experiment) -> dict:
    return {
        "id": experiment.id,
        "name": experiment.name,
        "description": experiment.description,
        "notes": experiment.notes,
        "tags": experiment.tags,
        "created_at": experiment.created_at,
        "updated_at": experiment.updated_at,
        "runs": records.run_count(session, experiment.id),
    }
