"""Calibrations: the model fitted to robot runs, stored as a named preset (docs/calibration.md)."""

from __future__ import annotations

import functools
from typing import Annotated

from fastapi import APIRouter, Path

from backend import schemas
from backend.api.deps import AUTHORIZED, Db, QuickCompute
from backend.services import calibrations
from backend.workers.pools import ComputePool

router = APIRouter(prefix="/api/v1/calibrations", tags=["calibrations"])
PresetPath = Annotated[str, Path(min_length=1, max_length=64, pattern=calibrations.PRESET_NAME.pattern)]


@router.post("", status_code=201, dependencies=AUTHORIZED, response_model=schemas.CalibrationOut)
async def create_calibration(body: schemas.CalibrationCreate, db: Db, compute: QuickCompute) -> schemas.CalibrationOut:
    """Fit ``alpha``, ``c_zeta``, ``c_psi`` and the legs' offsets to the runs; stored as preset ``name``."""
    return await db(calibrations.create, body, fit=functools.partial(_fit_in_worker, compute))


@router.get("", response_model=schemas.CalibrationList)
async def list_calibrations(db: Db) -> schemas.CalibrationList:
    return await db(calibrations.list_calibrations)


@router.get("/{name}", response_model=schemas.CalibrationOut)
async def get_calibration(name: PresetPath, db: Db) -> schemas.CalibrationOut:
    return await db(calibrations.get_calibration, name)


@router.delete("/{name}", status_code=204, dependencies=AUTHORIZED)
async def delete_calibration(name: PresetPath, db: Db) -> None:
    await db(calibrations.delete_preset, name)


def _fit_in_worker(compute: ComputePool, series, model):
    # Seconds of kernels at most (a few hundred pairs, two fits): the quick worker, not this thread's GIL.
    return compute.run(calibrations.fit_touchdowns, series, model)
