"""Quick calls for the control panel: computed, not stored, bounded in size and time.

Each runs in the service's quick compute worker (backend/workers/pools.py) and is awaited on
the event loop: no request thread waits, and the service's own process computes nothing — the
worker even encodes the JSON, which the route forwards as it is (the response models document it).
"""

from __future__ import annotations

from fastapi import APIRouter, Request
from fastapi.responses import Response

from backend import schemas
from backend.api.deps import QuickCompute, preset_resolved
from backend.services import simulation
from backend.workers.pools import as_json

router = APIRouter(prefix="/api/v1/sim", tags=["simulate"])


@router.post("/map", response_model=schemas.MapOut)
async def sim_map(body: schemas.MapIn, request: Request, compute: QuickCompute) -> Response:
    body = await preset_resolved(request, body)
    return _json(await compute.call(as_json, simulation.map_orbit, body))


@router.post("/trajectory", response_model=schemas.TrajectoryOut)
async def sim_trajectory(body: schemas.TrajectoryIn, request: Request, compute: QuickCompute) -> Response:
    """The sampled path in wall coordinates (nondimensional), for drawing; not stored."""
    body = await preset_resolved(request, body)
    return _json(await compute.call(as_json, simulation.trajectory_columns, body))


@router.post("/fixed-point", response_model=schemas.FixedPointOut)
async def sim_fixed_point(body: schemas.FixedPointIn, request: Request, compute: QuickCompute) -> Response:
    body = await preset_resolved(request, body)
    return _json(await compute.call(as_json, simulation.fixed_point, body))


def _json(encoded: bytes) -> Response:
    return Response(encoded, media_type="application/json")
