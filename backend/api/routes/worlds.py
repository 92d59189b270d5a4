"""Worlds: the lab's worlds stored by name (docs/worlds.md, "Worlds in the service")."""

from __future__ import annotations

from fastapi import APIRouter

from backend import schemas
from backend.api.deps import AUTHORIZED, Cursor, Db, PageLimit, RecordId, Who
from backend.services import worlds

router = APIRouter(prefix="/api/v1/worlds", tags=["worlds"])


@router.post("", status_code=201, dependencies=AUTHORIZED, response_model=schemas.WorldOut)
async def create_world(body: schemas.WorldCreate, db: Db, who: Who) -> schemas.WorldOut:
    """Store a world as ``name``: the §8 JSON as posted (a malformed one is a 422 naming the side
    and the point or segment), a named world, or a random one from its seed."""
    return await db(worlds.create, body, who)


@router.get("", response_model=schemas.WorldPage)
async def list_worlds(db: Db, limit: PageLimit = 50, cursor: Cursor = None) -> schemas.WorldPage:
    """Worlds, newest first, each with how many runs and jobs use it, and their ``total``."""
    return await db(worlds.list_page, limit=limit, cursor=cursor)


@router.get("/{world_id}", response_model=schemas.WorldOut)
async def get_world(world_id: RecordId, db: Db) -> schemas.WorldOut:
    """The world, ``world`` as it was posted (coordinates exact): what ``parkour world`` and the
    panel read and export."""
    return await db(worlds.get, world_id)


@router.patch("/{world_id}", dependencies=AUTHORIZED, response_model=schemas.WorldOut)
async def rename_world(world_id: RecordId, body: schemas.WorldRename, db: Db) -> schemas.WorldOut:
    return await db(worlds.rename, world_id, body)


@router.delete("/{world_id}", status_code=204, dependencies=AUTHORIZED)
async def delete_world(world_id: RecordId, db: Db) -> None:
    """Delete a world no run or job uses; one in use is a 409 naming a run or job that uses it."""
    await db(worlds.delete, world_id)
