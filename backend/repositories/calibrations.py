"""Stored calibrations (:class:`~backend.store.models.ModelPreset`): by name, all of them, added
and deleted under the write lock."""

from __future__ import annotations

from sqlalchemy import select
from sqlalchemy.exc import IntegrityError
from sqlalchemy.orm import Session

from backend.errors import Conflict, NotFound
from backend.store.database import lock_for_write
from backend.store.models import ModelPreset


def named(session: Session, name: str) -> ModelPreset | None:
    """The stored preset called ``name``, or None."""
    return session.scalar(select(ModelPreset).where(ModelPreset.name == name))


def exists(session: Session, name: str) -> bool:
    return session.scalar(select(ModelPreset.id).where(ModelPreset.name == name)) is not None


def get(session: Session, name: str) -> ModelPreset:
    """The stored preset called ``name``; :class:`NotFound` if there is none."""
    preset = named(session, name)
    if preset is None:
        raise NotFound("preset", name)
    return preset


def all_presets(session: Session) -> list[ModelPreset]:
    """Every stored preset, oldest first."""
    return list(session.scalars(select(ModelPreset).order_by(ModelPreset.id)))


def add(session: Session, preset: ModelPreset) -> None:
    """Add ``preset`` under the write lock, flushed (the caller commits); a :class:`Conflict` if one
    of its name was stored meanwhile."""
    lock_for_write(session)
    session.add(preset)
    try:
        session.flush()
    except IntegrityError:
        session.rollback()
        raise Conflict(f"a preset named {preset.name!r} exists; choose another name or delete it") from None


def delete(session: Session, name: str) -> None:
    """Delete the stored preset ``name`` under the write lock (the caller commits); :class:`NotFound` if none."""
    lock_for_write(session)
    session.delete(get(session, name))
