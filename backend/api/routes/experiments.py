"""Experiments: named groups of runs with notes and tags."""

from __future__ import annotations

from fastapi import APIRouter
from sqlalchemy.orm import Session

from backend import schemas
from backend.api.deps import AUTHORIZED, Cursor, Db, PageLimit, RecordId
from backend.services import records

router = APIRouter(prefix="/api/v1/experiments", tags=["experiments"])


@router.post("", status_code=201, dependencies=AUTHORIZED, response_model=schemas.ExperimentOut)
def create_experiment(body: schemas.ExperimentCreate, db: Db):
    return experiment_out(db, records.create_experiment(db, body))


@router.get("", response_model=schemas.ExperimentPage)
def list_experiments(db: Db, limit: PageLimit = 50, cursor: Cursor = None):
    rows, next_cursor = records.list_experiments(db, limit=limit, cursor=cursor)
    return {"items": [experiment_out(db, row) for row in rows], "next_cursor": next_cursor}


@router.get("/{experiment_id}", response_model=schemas.ExperimentOut)
def get_experiment(experiment_id: RecordId, db: Db):
    return experiment_out(db, records.get_experiment(db, experiment_id))


@router.patch("/{experiment_id}", dependencies=AUTHORIZED, response_model=schemas.ExperimentOut)
def update_experiment(experiment_id: RecordId, body: schemas.ExperimentUpdate, db: Db):
    return experiment_out(db, records.update_experiment(db, experiment_id, body))


@router.delete("/{experiment_id}", status_code=204, dependencies=AUTHORIZED)
def delete_experiment(experiment_id: RecordId, db: Db) -> None:
    records.delete_experiment(db, experiment_id)


def experiment_out(db: Session, experiment) -> dict:
    return {
        "id": experiment.id,
        "name": experiment.name,
        "description": experiment.description,
        "notes": experiment.notes,
        "tags": experiment.tags,
        "created_at": experiment.created_at,
        "updated_at": experiment.updated_at,
        "runs": records.run_count(db, experiment.id),
    }
