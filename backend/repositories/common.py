"""What every repository shares: one row by id (or :class:`~backend.errors.NotFound`), one row
locked for a change, and keyset pages by id, newest first.

A change that depends on what it reads (an update, a delete, a run added to an experiment) takes
the write lock first and reads the rows fresh under it (:func:`locked`): concurrent edits of one
record serialise, each whole, instead of interleaving their reads and writes.
"""

from __future__ import annotations

from sqlalchemy import Select, select
from sqlalchemy.orm import Session

from backend.errors import NotFound
from backend.store.database import lock_for_write


def fetch(session: Session, model: type, identifier: int, what: str, **options):
    """The row of ``model`` with primary key ``identifier``; :class:`NotFound` names ``what`` if none."""
    row = session.get(model, identifier, **options)
    if row is None:
        raise NotFound(what, identifier)
    return row


def locked(session: Session, model: type, identifier: int, what: str):
    """:func:`fetch` for a change: under the write lock (SQLite), the row locked ``FOR UPDATE``
    (PostgreSQL), read fresh even if the session holds an older copy."""
    lock_for_write(session)
    return fetch(session, model, identifier, what, with_for_update=True, populate_existing=True)


def newest_first(model: type, limit: int, cursor: int | None) -> Select:
    """The query for one keyset page of ``model`` by ``id``, newest first (``limit + 1`` rows: see :func:`page`)."""
    query = select(model).order_by(model.id.desc()).limit(limit + 1)
    return query if cursor is None else query.where(model.id < cursor)


def page(rows: list, limit: int) -> tuple[list, int | None]:
    """A keyset page from ``limit + 1`` rows fetched newest first: the rows and the next cursor."""
    if len(rows) > limit:
        return rows[:limit], rows[limit - 1].id
    return rows, None
