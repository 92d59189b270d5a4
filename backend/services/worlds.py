"""Worlds: the lab's worlds stored by name (docs/worlds.md, "Worlds in the service") — created from
the §8 JSON as posted, from a named world or drawn at random, listed, read back exactly as posted,
renamed, deleted (refused while a run or job uses one, naming it).

A posted world is checked by sim_core's own reader (:func:`sim_core.world.files.world_from_document`),
so a malformed one is a 422 whose field names the side and the point or segment
(``world.left.points[3]``, ``world.right.mu[2]``); it is stored as posted, so that what comes back
is what was sent, to the last digit. Named and random worlds are stored as the §8 JSON in ``l0``.
"""

from __future__ import annotations

from sqlalchemy.orm import Session

from backend.errors import Conflict
from backend.repositories import worlds as stored
from backend.schemas.worlds import WorldCreate, WorldOut, WorldPage, WorldRename
from backend.services.presets import resolve_model
from backend.store.database import freeing_space
from backend.store.models import World
from sim_core.model.errors import ParameterError
from sim_core.world.files import world_from_document, world_to_document
from sim_core.world.named import named_world
from sim_core.world.random_world import random_world


def create(session: Session, body: WorldCreate, who: str | None = None) -> WorldOut:
    document, source = _document_of(session, body)
    world = stored.add(session, World(name=body.name, document=document, source=source, created_by=who))
    session.commit()
    return world_out(world, (0, 0))


def get(session: Session, world_id: int) -> WorldOut:
    world = stored.get(session, world_id)
    return world_out(world, stored.usage(session, [world.id]).get(world.id, (0, 0)))


def list_page(session: Session, *, limit: int, cursor: int | None) -> WorldPage:
    worlds, next_cursor = stored.page(session, limit=limit, cursor=cursor)
    used = stored.usage(session, [world.id for world in worlds])
    items = [world_out(world, used.get(world.id, (0, 0))) for world in worlds]
    return WorldPage(items=items, next_cursor=next_cursor, total=stored.count(session))


def rename(session: Session, world_id: int, body: WorldRename) -> WorldOut:
    world = stored.rename(session, world_id, body.name)
    session.commit()
    return world_out(world, stored.usage(session, [world.id]).get(world.id, (0, 0)))


def delete(session: Session, world_id: int) -> None:
    """Delete a world no run or job uses (a :class:`Conflict` naming one that does)."""

    def remove() -> None:
        world = stored.locked(session, world_id)
        user = stored.first_user(session, world_id)
        if user is not None:
            runs, jobs = stored.usage(session, [world_id]).get(world_id, (0, 0))
            raise Conflict(
                f"world {world_id} ({world.name!r}) is used by {user} ({runs} runs and {jobs} jobs in all); "
                "it is their record and cannot be deleted"
            )
        stored.delete(session, world)
        session.commit()

    freeing_space(session, remove)


def world_in_l0(session: Session, world_id: int, preset: str) -> dict:
    """The stored world ``world_id`` as the §8 JSON in ``l0`` (a world posted in metres read with
    ``preset``'s leg length), named as stored: what a simulation or job in it is handed.
    :class:`NotFound` if there is none."""
    world = stored.get(session, world_id)
    robot = resolve_model(session, preset).robot
    return world_to_document(world_from_document(world.document, robot.leg_length)) | {"name": world.name}


def world_out(world: World, used: tuple[int, int]) -> WorldOut:
    return WorldOut(id=world.id, name=world.name, world=world.document, source=world.source,
                    created_at=world.created_at, created_by=world.created_by, runs=used[0], jobs=used[1])  # fmt: skip


def _document_of(session: Session, body: WorldCreate) -> tuple[dict, str]:
    """The §8 JSON to store and where it came from; a ParameterError naming the field otherwise."""
    robot = resolve_model(session, body.preset).robot
    if body.world is not None:
        try:
            world_from_document(body.world, robot.leg_length)
        except ParameterError as error:
            raise ParameterError(f"world.{error.field}", error.message) from None
        return body.world, "posted"
    if body.named is not None:
        try:
            world = named_world(body.named, robot.to_model().d_hat)
        except ParameterError as error:
            raise ParameterError("named", error.message) from None
        return world_to_document(world), f"named:{body.named}"
    options = body.random.model_dump(exclude_none=True)
    seed = options.pop("seed")
    try:
        world = random_world(seed, **options)
    except ParameterError as error:
        raise ParameterError(f"random.{error.field}", error.message) from None
    return world_to_document(world), f"random:{seed}"
