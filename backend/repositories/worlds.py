"""Stored worlds (:class:`~backend.store.models.World`): by id, a page of them, added, renamed and
deleted under the write lock, and who uses one (runs and jobs)."""

from __future__ import annotations

from sqlalchemy import func, select
from sqlalchemy.exc import IntegrityError
from sqlalchemy.orm import Session

from backend.errors import Conflict, NotFound
from backend.store.database import lock_for_write
from backend.store.models import Job, Run, World


def get(session: Session, world_id: int) -> World:
    world = session.get(World, world_id)
    if world is None:
        raise NotFound("world", world_id)
    return world


def page(session: Session, *, limit: int, cursor: int | None) -> tuple[list[World], int | None]:
    """Worlds newest first, ``limit`` a page, from below ``cursor`` (an id); the next cursor or None."""
    query = select(World).order_by(World.id.desc()).limit(limit + 1)
    if cursor is not None:
        query = query.where(World.id < cursor)
    worlds = list(session.scalars(query))
    more = len(worlds) > limit
    return worlds[:limit], (worlds[limit - 1].id if more else None)


def count(session: Session) -> int:
    return session.scalar(select(func.count(World.id))) or 0


def usage(session: Session, world_ids: list[int]) -> dict[int, tuple[int, int]]:
    """``{world id: (runs, jobs)}`` using each of ``world_ids`` (absent: none)."""
    counts: dict[int, list[int]] = {}
    for index, model in enumerate((Run, Job)):
        rows = session.execute(
            select(model.world_id, func.count(model.id)).where(model.world_id.in_(world_ids)).group_by(model.world_id)
        )
        for world_id, used in rows:
            counts.setdefault(world_id, [0, 0])[index] = used
    return {world_id: (runs, jobs) for world_id, (runs, jobs) in counts.items()}


def first_user(session: Session, world_id: int) -> str | None:
    """A run or job that uses the world, said for a person ("run 12", "job 3"), or None."""
    for what, model in (("run", Run), ("job", Job)):
        found = session.scalar(select(model.id).where(model.world_id == world_id).order_by(model.id).limit(1))
        if found is not None:
            return f"{what} {found}"
    return None


def add(session: Session, world: World) -> World:
    """Add ``world`` under the write lock, flushed (the caller commits); a :class:`Conflict` if its
    name is taken."""
    lock_for_write(session)
    _check_name_free(session, world.name)
    session.add(world)
    _flush_named(session, world.name)
    return world


def rename(session: Session, world_id: int, name: str) -> World:
    lock_for_write(session)
    world = get(session, world_id)
    if name != world.name:
        _check_name_free(session, name)
        world.name = name
        _flush_named(session, name)
    return world


def delete(session: Session, world: World) -> None:
    session.delete(world)


def locked(session: Session, world_id: int) -> World:
    """The world, read fresh under the write lock."""
    lock_for_write(session)
    return get(session, world_id)


def _check_name_free(session: Session, name: str) -> None:
    taken = session.scalar(select(World.id).where(World.name == name))
    if taken is not None:
        raise Conflict(f"a world named {name!r} exists (world {taken}); choose another name or rename that one")


def _flush_named(session: Session, name: str) -> None:
    try:
        session.flush()
    except IntegrityError:  # stored meanwhile by another writer
        session.rollback()
        raise Conflict(f"a world named {name!r} exists; choose another name") from None
