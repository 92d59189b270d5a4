"""Which runs a list, an export or an aggregate covers (:class:`RunFilter`), as SQL conditions, and
how many runs a filter selects (:func:`matching_count`).

Every criterion but the search ``q`` reads an index. A page's total is a COUNT over the runs that
match. On SQLite each connection keeps the counts it made, and the orders of ids that pages were
cut from (:class:`ListCache`), while no run or tag has changed (the runs' version, which triggers
move: :func:`store_stamp`): paging through one filter and sort counts and sorts it once.
"""

from __future__ import annotations

import datetime
import functools
from array import array
from collections import OrderedDict
from dataclasses import dataclass

from sqlalchemy import Select, String, bindparam, func, select
from sqlalchemy.orm import Session

from backend.store.models import Run, RunTag


@dataclass(frozen=True)
class RunFilter:
    """Which runs a list, export or aggregate covers; None leaves a criterion out. Ranges are
    inclusive; ``created_before`` is exclusive. ``end_reason`` matches a reason as stored or every
    reason of its kind ("error" matches "error: …"); ``q`` is text found in a run's notes or in one
    of its tags, case-insensitively (ASCII letters on SQLite)."""

    experiment_id: int | None = None
    kind: str | None = None
    status: str | None = None
    tag: str | None = None
    failure_code: str | None = None
    end_reason: str | None = None
    loop: str | None = None
    controller: str | None = None
    zeta0_min: float | None = None
    zeta0_max: float | None = None
    psi0_min: float | None = None
    psi0_max: float | None = None
    created_after: datetime.datetime | None = None
    created_before: datetime.datetime | None = None
    q: str | None = None


def _containing(text: str) -> str:
    """A LIKE pattern (escaped with ``\\``) for values that contain ``text``."""
    return "%" + text.replace("\\", "\\\\").replace("%", "\\%").replace("_", "\\_") + "%"


def _same_or_kind_of(v):
    # "error" matches "error" and "error: …": a range over the index, not a LIKE (which SQLite's
    # case-insensitive LIKE cannot read from an index).
    return (Run.end_reason == v) | ((Run.end_reason >= v + ":") & (Run.end_reason < v + ";"))


def _search(pattern):
    return Run.notes.ilike(pattern, escape="\\") | Run.id.in_(
        select(RunTag.run_id).where(RunTag.tag.ilike(pattern, escape="\\"))
    )


# Each filter criterion as the condition it puts on a query, given its value (a literal, or a
# bindparam in a cached page statement; see _BOUND for the values a criterion binds). Every
# criterion but q has an index; q reads the notes of the runs and the tags' index.
_CONDITIONS = {
    "experiment_id": lambda v: Run.experiment_id == v,
    "kind": lambda v: Run.kind == v,
    "status": lambda v: Run.status == v,
    "failure_code": lambda v: Run.failure_code == v,
    "end_reason": _same_or_kind_of,
    "loop": lambda v: Run.loop == v,
    "controller": lambda v: Run.controller == v,
    "zeta0_min": lambda v: Run.zeta0 >= v,
    "zeta0_max": lambda v: Run.zeta0 <= v,
    "psi0_min": lambda v: Run.psi0_deg >= v,
    "psi0_max": lambda v: Run.psi0_deg <= v,
    "created_after": lambda v: Run.created_at >= v,
    "created_before": lambda v: Run.created_at < v,
    "tag": lambda v: Run.id.in_(select(RunTag.run_id).where(RunTag.tag == v)),
    "q": _search,
}
_BOUND = {"q": _containing}  # a criterion's value as its condition takes it (the others: as given)
_TYPED = {"end_reason": String, "q": String}  # bindparams whose type a concatenation or LIKE needs


def bound_values(where: RunFilter) -> dict:
    """The criteria ``where`` sets, by name, each as its condition takes its value."""
    values = {}
    for name in _CONDITIONS:
        value = getattr(where, name)
        if value is not None:
            values[name] = _BOUND[name](value) if name in _BOUND else value
    return values


def filtered(query: Select, where: RunFilter) -> Select:
    """``query`` restricted to the runs ``where`` selects."""
    for name, value in bound_values(where).items():
        query = query.where(_CONDITIONS[name](value))
    return query


def where_criteria(query: Select, criteria: tuple[str, ...]) -> Select:
    """``query`` with the conditions of ``criteria``, each value a bindparam named as its criterion."""
    for criterion in criteria:
        query = query.where(_CONDITIONS[criterion](bindparam(criterion, type_=_TYPED.get(criterion))))
    return query


@functools.lru_cache(maxsize=256)
def _count_statement(criteria: tuple[str, ...]) -> Select:
    return where_criteria(select(func.count()).select_from(Run), criteria)


def matching_count(session: Session, where: RunFilter) -> int:
    """How many runs ``where`` selects: one COUNT, or on SQLite the one counted before for the same
    criteria on this connection if no run has changed since (:func:`list_cache`). Paging through a
    filter counts it once, not once per page."""
    values = bound_values(where)
    connection = session.connection()
    cache = list_cache(connection)
    key = tuple(values.items())
    if cache is not None and key in cache.counts:
        return cache.counts[key]
    count = connection.execute(_count_statement(tuple(values)), values).scalar_one()
    if cache is not None:
        cache.keep_count(key, count)
    return count


class ListCache:
    """What one SQLite connection has read of the run list while the runs' version stood at
    ``stamp``: counts by criteria, and whole orders of matching ids by (criteria, sort), the
    least recently used dropped past :data:`IDS_KEPT` ids (8 bytes each)."""

    def __init__(self, stamp: int):
        self.stamp = stamp
        self.counts: dict[tuple, int] = {}
        self.orders: OrderedDict[tuple, array] = OrderedDict()
        self.ids_kept = 0
        self.asked: set[tuple] = set()  # orders asked for under this stamp, kept or not

    def asked_again(self, key: tuple) -> bool:
        """Whether the order ``key`` was asked for before under this stamp (and note that it was
        now): an order worth reading whole and keeping is one asked for twice before a write."""
        if key in self.asked:
            return True
        if len(self.asked) >= COUNTS_KEPT:
            self.asked.clear()
        self.asked.add(key)
        return False

    def keep_count(self, key: tuple, count: int) -> None:
        if len(self.counts) >= COUNTS_KEPT:
            self.counts.clear()
        self.counts[key] = count

    def order(self, key: tuple) -> array | None:
        ids = self.orders.get(key)
        if ids is not None:
            self.orders.move_to_end(key)
        return ids

    def keep_order(self, key: tuple, ids: array) -> None:
        self.orders[key] = ids
        self.ids_kept += len(ids)
        while self.ids_kept > IDS_KEPT and len(self.orders) > 1:
            _key, oldest = self.orders.popitem(last=False)
            self.ids_kept -= len(oldest)


COUNTS_KEPT = 256
IDS_KEPT = 2_000_000  # 16 MB of ids a connection keeps at most (20 orders of 100,000 runs)
_CACHE = "parkourlab.run_list"  # a pooled SQLite connection's info: its ListCache


def list_cache(connection) -> ListCache | None:
    """The connection's :class:`ListCache` for the runs as they are now (a new one once they have
    changed), or None where nothing may be kept: on other databases, and while the connection has
    a transaction open (its uncommitted writes may yet be rolled back)."""
    stamp = store_stamp(connection)
    if stamp is None:
        return None
    cache = connection.info.get(_CACHE)
    if cache is None or cache.stamp != stamp:
        cache = connection.info[_CACHE] = ListCache(stamp)
    return cache


def store_stamp(connection) -> int | None:
    """The runs' version (``store_versions``, moved by SQLite's triggers whenever any connection adds
    or deletes a run or a tag or changes what a list filters or sorts by — not a live run's
    duration alone: migration 0008), or None when it cannot be relied on: on other databases, and
    while ``connection`` has a transaction open. Read before what is kept under it, so a change
    committed in between makes the next read see a new version, never an old one."""
    if connection.dialect.name != "sqlite" or connection.connection.dbapi_connection.in_transaction:
        return None
    return connection.exec_driver_sql(_STAMP).scalar_one_or_none()


_STAMP = "SELECT version FROM store_versions WHERE name = 'runs'"
