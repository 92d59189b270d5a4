"""What a read worker's SQLite connection keeps of the run list between reads: each filter's total
(:func:`matching_count`) and the orders of ids that pages were cut from (:class:`ListCache`).

The store's stamp (:func:`store_stamp`) says what has changed since: the runs' version, which
SQLite's triggers move whenever a list could see a change (migration 0008), and the ``reshaped``
version, which they move only for changes to runs older than the newest one (a run deleted, an
old run edited or retagged: migration 0010). Orders are kept while the runs are not reshaped:
the runs added since (and the newest one, which may have changed) are put into them when next
asked for, at the end of an order by id, by bisection in another (:func:`kept_order`). A total is
kept as a :class:`Base` — how many matching runs were older than the newest run when it was
counted — which holds until the runs are reshaped: after a write that only adds runs (or changes
the newest one) the total is its base plus the runs from that id on, counted afresh through the
id's range. The History under writes thus counts a few new rows per page, not 100,000.
PostgreSQL keeps nothing (no triggers): each page counts.
"""

from __future__ import annotations

import functools
from array import array
from collections import OrderedDict
from dataclasses import dataclass

import numpy
from sqlalchemy import Integer, Select, bindparam, case, func, select
from sqlalchemy.orm import Session

from backend.repositories.run_filters import RunFilter, bound_values, where_criteria
from backend.store.models import Run


@dataclass(frozen=True)
class Stamp:
    """The store as a connection saw it in one read: ``version`` (any change a list sees),
    ``reshaped`` (the changes other than to the newest run) and ``newest``, the largest run id (0:
    no runs)."""

    version: int
    reshaped: int
    newest: int


@dataclass(frozen=True)
class Base:
    """How many runs a filter matched below the run id ``newest`` (the largest when counted): its
    total is ``older`` plus the matching runs from ``newest`` on, while the runs are not reshaped."""

    older: int
    newest: int


class ListCache:
    """What one SQLite connection has read of the run list: totals and whole orders of matching
    ids at ``stamp`` (the least recently used orders dropped past :data:`IDS_KEPT` ids, 8 bytes
    each), and each filter's :class:`Base`, kept across stamps of the same ``reshaped`` version;
    so are the orders by id (whose new runs all go at one end), marked ``behind`` until
    :func:`kept_order` adds the runs since to them. An order's key is (criteria, sort)."""

    def __init__(self, stamp: Stamp, bases: dict[tuple, Base] | None = None):
        self.stamp = stamp
        self.counts: dict[tuple, int] = {}
        self.bases: dict[tuple, Base] = {} if bases is None else bases
        self.orders: OrderedDict[tuple, array] = OrderedDict()
        self.newest: dict[tuple, int] = {}  # each order's stamp.newest when it was read
        self.behind: set[tuple] = set()  # orders kept from an earlier stamp: the runs since not in them yet
        self.ids_kept = 0
        self.asked: set[tuple] = set()  # orders asked for under this stamp, kept or not

    def renewed(self, stamp: Stamp) -> ListCache:
        """The cache for the store at ``stamp``: nothing of this one but its bases and its orders,
        and those only if the runs have not been reshaped since (then each order is behind: the
        runs since its newest go into it when it is next asked for, :func:`kept_order`)."""
        if stamp.reshaped != self.stamp.reshaped:
            return ListCache(stamp)
        renewed = ListCache(stamp, self.bases)
        for key, ids in self.orders.items():
            renewed.keep_order(key, ids, self.newest[key])
            renewed.behind.add(key)
        return renewed

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

    def keep_base(self, key: tuple, base: Base) -> None:
        if len(self.bases) >= COUNTS_KEPT:
            self.bases.clear()
        self.bases[key] = base

    def order(self, key: tuple) -> array | None:
        ids = self.orders.get(key)
        if ids is not None:
            self.orders.move_to_end(key)
        return ids

    def keep_order(self, key: tuple, ids: array, newest: int) -> None:
        """Keep ``ids``, the order ``key`` read after the store's stamp showed ``newest`` as the
        newest run."""
        self.forget_order(key)
        self.orders[key], self.newest[key] = ids, newest
        self.ids_kept += len(ids)
        while self.ids_kept > IDS_KEPT and len(self.orders) > 1:
            self.forget_order(next(iter(self.orders)))

    def forget_order(self, key: tuple) -> None:
        ids = self.orders.pop(key, None)
        if ids is not None:
            self.ids_kept -= len(ids)
            del self.newest[key]
            self.behind.discard(key)


COUNTS_KEPT = 256
IDS_KEPT = 2_000_000  # 16 MB of ids a connection keeps at most (20 orders of 100,000 runs)
RECOUNT_AFTER = 2_000  # runs added since a base from which its total is counted whole again
_CACHE = "parkourlab.run_list"  # a pooled SQLite connection's info: its ListCache


def matching_count(session: Session, where: RunFilter) -> int:
    """How many runs ``where`` selects. On SQLite, once per connection and stamp: the total kept
    for the same criteria since the last change, else the base's plus the runs from its id on,
    else one COUNT, which sets the base. Paging through a filter counts it once; a write that
    adds a run costs the next page a count of the runs since the base, not of every run."""
    values = bound_values(where)
    criteria = tuple(values)
    connection = session.connection()
    cache = list_cache(connection)
    if cache is None:
        return connection.execute(_count_statement(criteria), values).scalar_one()
    key = tuple(values.items())
    if key in cache.counts:
        return cache.counts[key]
    base = cache.bases.get(key)
    if base is not None and cache.stamp.newest - base.newest <= RECOUNT_AFTER:
        since = connection.execute(_count_statement(criteria, since=True), values | {"since": base.newest})
        count = base.older + since.scalar_one()
    else:
        count, older = connection.execute(_base_statement(criteria), values | {"newest": cache.stamp.newest}).one()
        cache.keep_base(key, Base(older, cache.stamp.newest))
    cache.keep_count(key, count)
    return count


def kept_order(connection, cache: ListCache, key: tuple, values: dict) -> array | None:
    """The whole order ``key`` (criteria, sort) of the matching ids if the connection keeps it, as
    the store is now: an order kept from before new runs came has its runs from the id that was
    newest when it was read on dropped, and the matching runs from that id on read (through the
    id's range) and put in: at its end in an order by id, each at its place in another
    (:func:`_placed`). None where nothing is kept, or too many runs came since."""
    ids = cache.order(key)
    if ids is None or key not in cache.behind:
        return ids
    newest = cache.newest[key]
    if cache.stamp.newest - newest > RECOUNT_AFTER:
        cache.forget_order(key)
        return None
    descending = key[1].startswith("-")
    since = connection.execute(_since_ids_statement(tuple(values), descending), values | {"since": newest})
    since = array("q", since.scalars())
    if key[1].lstrip("-") != "id":
        ids = _placed(connection, ids, newest, since, key[1])
        if ids is None:
            cache.forget_order(key)
            return None
    elif descending:  # the newest runs first: drop them from the front, put the runs since there
        cut = 0
        while cut < len(ids) and ids[cut] >= newest:
            cut += 1
        ids = since + ids[cut:]
    else:
        cut = len(ids)
        while cut and ids[cut - 1] >= newest:
            cut -= 1
        ids = ids[:cut] + since
    cache.keep_order(key, ids, cache.stamp.newest)
    return ids


PLACED_AT_MOST = 64  # runs since an order was read that are put in one by one; more: it is read again


def _placed(connection, ids: array, newest: int, since: array, sort: str) -> array | None:
    """``ids``, an order by ``sort``'s column then id, without its runs from ``newest`` on (the only
    runs that can have changed while the runs were not reshaped) and with the runs ``since`` each
    at its place: found by bisection, reading the sorted column of the runs it compares with (17
    reads at 100,000 runs; a whole order read again took tens of ms after every write). None when
    more than :data:`PLACED_AT_MOST` runs came."""
    if len(since) > PLACED_AT_MOST:
        return None
    name, descending = sort.lstrip("-"), sort.startswith("-")
    read = connection.connection.dbapi_connection.cursor()
    statement = f'SELECT "{name}" FROM runs WHERE id = ?'  # name: one of the sorts' columns

    def key(run_id: int) -> tuple:  # as SQL orders them: nulls the smallest, then ties by id
        value = read.execute(statement, (run_id,)).fetchone()[0]
        return (value is not None, 0 if value is None else value, run_id)

    kept = numpy.frombuffer(ids, dtype=numpy.int64)
    kept = kept[kept < newest]
    coming = sorted(((key(run_id), run_id) for run_id in since), reverse=descending)
    places = []
    for wanted, _ in coming:
        low, high = 0, len(kept)
        while low < high:
            middle = (low + high) // 2
            here = key(int(kept[middle]))
            if (here > wanted) if descending else (here < wanted):
                low = middle + 1
            else:
                high = middle
        places.append(low)
    merged = numpy.insert(kept, places, [run_id for _, run_id in coming]) if coming else kept
    placed = array("q")
    placed.frombytes(merged.astype(numpy.int64).tobytes())
    return placed


@functools.lru_cache(maxsize=128)
def _since_ids_statement(criteria: tuple[str, ...], descending: bool) -> Select:
    order = Run.id.desc() if descending else Run.id.asc()
    return where_criteria(select(Run.id), criteria, since=True).order_by(order)


@functools.lru_cache(maxsize=512)
def _count_statement(criteria: tuple[str, ...], since: bool = False) -> Select:
    return where_criteria(select(func.count()).select_from(Run), criteria, since=since)


@functools.lru_cache(maxsize=256)
def _base_statement(criteria: tuple[str, ...]) -> Select:
    """The matching runs, and those of them below the id bound as ``newest``: one read, so both are
    counted in the same state of the store."""
    older = func.count(case((Run.id < bindparam("newest", type_=Integer), 1)))
    return where_criteria(select(func.count(), older).select_from(Run), criteria)


def list_cache(connection) -> ListCache | None:
    """The connection's :class:`ListCache` for the store as it is now (renewed once it has
    changed), or None where nothing may be kept: on other databases, and while the connection has
    a transaction open (its uncommitted writes may yet be rolled back)."""
    stamp = store_stamp(connection)
    if stamp is None:
        return None
    cache = connection.info.get(_CACHE)
    if cache is None:
        cache = connection.info[_CACHE] = ListCache(stamp)
    elif cache.stamp != stamp:
        cache = connection.info[_CACHE] = cache.renewed(stamp)
    return cache


def store_stamp(connection) -> Stamp | None:
    """The store's :class:`Stamp`, read in one statement, or None when it cannot be relied on: on
    other databases, and while ``connection`` has a transaction open. Read before what is kept
    under it, so a change committed in between makes the next read see a new stamp, never an old
    one. (A live run's duration alone moves no version: migration 0008.)"""
    if connection.dialect.name != "sqlite" or connection.connection.dbapi_connection.in_transaction:
        return None
    return Stamp(*connection.exec_driver_sql(_STAMP).one())


_STAMP = (
    "SELECT (SELECT version FROM store_versions WHERE name = 'runs'), "
    "(SELECT version FROM store_versions WHERE name = 'runs_reshaped'), "
    "(SELECT coalesce(max(id), 0) FROM runs)"
)
