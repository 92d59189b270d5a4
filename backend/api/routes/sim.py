"""Quick calls for the control panel: computed, not stored, bounded in size and time.

Each runs in the service's quick compute worker (backend/workers/pools.py) and is awaited on
the event loop: no request thread waits, and the service's own process computes nothing — the
worker even encodes the JSON, which the route forwards as it is (the response models document it).
"""

from __future__ import annotations

from fastapi import APIRouter
from fastapi.responses import Response

from backend import schemas
from backend.api.deps import Db, QuickCompute
from backend.services import quick_calls

router = APIRouter(prefix="/api/v1/sim", tags=["simulate"])


@router.post("/map", response_model=schemas.MapOut)
async def sim_map(body: schemas.MapIn, database: Db, compute: QuickCompute) -> Response:
    return _json(await quick_calls.computed(database, compute, quick_calls.map_orbit, body))


@router.post("/trajectory", response_model=schemas.TrajectoryOut)
async def sim_trajectory(body: schemas.TrajectoryIn, database: Db, compute: QuickCompute) -> Response:
    """The sampled path in wall coordinates (nondimensional), for drawing; not stored."""
    return _json(await quick_calls.computed(database, compute, quick_calls.trajectory_columns, body))


@router.post("/fixed-point", response_model=schemas.FixedPointOut)
async def sim_fixed_point(body: schemas.FixedPointIn, database: Db, compute: QuickCompute) -> Response:
    return _json(await quick_calls.computed(database, compute, quick_calls.fixed_point, body))


def _json(encoded: bytes) -> Response:
    return Response(encoded, media_type="application/json")
