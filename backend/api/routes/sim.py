"""Quick calls for the control panel: computed, not stored, bounded in size."""

from __future__ import annotations

from fastapi import APIRouter

from backend import schemas
from backend.services import simulation

router = APIRouter(prefix="/api/v1/sim", tags=["simulate"])


@router.post("/map")
def sim_map(body: schemas.MapIn) -> dict:
    return simulation.map_orbit(body)


@router.post("/trajectory")
def sim_trajectory(body: schemas.TrajectoryIn) -> dict:
    """The sampled path in wall coordinates (nondimensional), for drawing; not stored."""
    return simulation.trajectory_columns(body)


@router.post("/fixed-point")
def sim_fixed_point(body: schemas.FixedPointIn) -> dict:
    return simulation.fixed_point(body)
