"""Runs in the store: the one place a run's row is built, and the SQL that reads, relabels, groups
and exports runs.

A new run is a :class:`RunRecord` (what a simulation, a live robot run or a replay produced);
:func:`add_run` turns it into the row, with the indexed copies of its parameters (alpha, the first
leg's psi0 and zeta0) derived here and nowhere else. Lists and exports read plain rows of the
columns they show (:data:`LISTED`), never ORM objects or the results and trajectory blobs: a page
of 50 costs a fraction of a millisecond of SQL and no JSON it does not return.
"""

from __future__ import annotations

import functools
import json
from array import array
from dataclasses import asdict

from sqlalchemy import Float, Integer, Select, Text, bindparam, case, cast, func, select
from sqlalchemy.orm import Session
from sqlalchemy.orm.attributes import set_committed_value

from backend.repositories.common import fetch, locked
from backend.repositories.run_filters import RunFilter, bound_values, filtered, where_criteria
from backend.repositories.run_list_cache import kept_order, list_cache, matching_count
from backend.store.models import Run, RunTag
from backend.store.run_record import RunRecord

# The columns of a listed run (the API's RunOut less its tags), read as plain rows; its JSON
# columns come as text (LISTED_JSON) and a page decodes them in one call (listed_page).
LISTED_JSON = ("model", "controls", "start_state")
LISTED = (Run.id, Run.experiment_id, Run.world_id, Run.kind, Run.status, Run.created_at, Run.duration_s,
          Run.code_version, Run.jumps, Run.jumps_completed, Run.failure_code, Run.climb, Run.notes, Run.end_reason,
          Run.loop, Run.controller, Run.target, Run.touchdowns, Run.created_by, Run.notes_by,
          Run.trajectory.is_not(None).label("has_trajectory"),
          *(cast(getattr(Run, name), Text).label(name) for name in LISTED_JSON))  # fmt: skip
# A run's tags as one text (group_concat on SQLite, string_agg on PostgreSQL), split by a character
# no tag can hold (a tag is letters, digits and . _ : / -: schemas.common.Label).
TAG_SEPARATOR = "\x1f"
_TAG_LIST = (
    select(func.aggregate_strings(RunTag.tag, TAG_SEPARATOR)).where(RunTag.run_id == Run.id).scalar_subquery()
).label("tag_list")
# What an export reads of each run: the record's own columns, then its JSON columns as text.
JSON_COLUMNS = ("model", "controls", "start_state")
EXPORTED = (Run.id, Run.experiment_id, Run.world_id, Run.kind, Run.status, Run.created_at, Run.duration_s,
            Run.code_version, Run.notes, Run.jumps, Run.jumps_completed, Run.failure_code, Run.climb, Run.end_reason,
            Run.loop, Run.controller, Run.target, Run.touchdowns, Run.created_by, Run.notes_by,
            *(cast(getattr(Run, name), Text).label(name) for name in JSON_COLUMNS))  # fmt: skip
# What a list sorts by: each an indexed column (id, then the column's order; -name: descending).
SORTED_BY = ("id", "created_at", "climb", "zeta0", "psi0_deg", "duration_s", "jumps_completed", "kind", "status",
             "end_reason", "loop", "controller", "target", "failure_code")  # fmt: skip
SORTS = tuple(sort for name in SORTED_BY for sort in (f"-{name}", name))
NULLABLE_SORTS = frozenset({"end_reason", "controller", "target", "failure_code"})  # nulls count as the smallest
RECORDED_KINDS = ("robot", "replay")  # runs measured on the robot (a replay analyses a robot run again)
END_REASON_LENGTH = 200
EXPORT_BATCH = 1000


def add_run(
    session: Session, record: RunRecord, *, experiment_id: int | None = None, created_by: str | None = None
) -> Run:
    """Add ``record`` to the session as a new run row made by ``created_by`` (the caller commits);
    its tags deduplicated and sorted, its filter columns copied from its model and first leg."""
    columns = asdict(record)
    tags = columns.pop("tags")
    psi0_deg, zeta0 = record.controls[0]
    columns |= outcome_columns(record.kind, record.results)
    run = Run(experiment_id=experiment_id, alpha=record.model["alpha"], psi0_deg=psi0_deg, zeta0=zeta0,
              created_by=created_by, **columns)  # fmt: skip
    run.run_tags = [RunTag(tag=tag) for tag in sorted(set(tags))]
    session.add(run)
    return run


def outcome_columns(kind: str, results: dict) -> dict:
    """A run's columns of how it ended and how it was driven, from what it stored in ``results``:
    ``end_reason`` (a robot run's, e.g. "e-stop"; None for a simulation or a replay),
    ``loop`` ("closed" when a robot run — or the robot run a replay analyses — held a height,
    else "open"), ``controller`` ("pid" for today's closed loop), ``target`` (its height [m]) and,
    for a robot or replay run, the ``touchdowns`` it recorded. Migration 0008 copied the same
    for the runs stored before it."""
    closed_loop = results.get("closed_loop") if kind in RECORDED_KINDS else None
    end_reason = results.get("end_reason") if kind == "robot" else None
    return {
        "end_reason": end_reason[:END_REASON_LENGTH] if end_reason else None,
        "loop": "closed" if closed_loop else "open",
        "controller": closed_loop.get("controller", "pid") if closed_loop else None,
        "target": closed_loop.get("target_m") if closed_loop else None,
        "touchdowns": len(results.get("touchdowns") or ()) if kind in RECORDED_KINDS else None,
    }


def set_outcome(run: Run) -> None:
    """Set ``run``'s :func:`outcome_columns` from its results as they are now (a live run that ended)."""
    for name, value in outcome_columns(run.kind, run.results).items():
        setattr(run, name, value)


def get_run(session: Session, run_id: int) -> Run:
    return fetch(session, Run, run_id, "run")


def find(session: Session, run_id: int | None) -> Run | None:
    """The run, or None if there is none with that id."""
    return None if run_id is None else session.get(Run, run_id)


def locked_run(session: Session, run_id: int) -> Run:
    """The run, read fresh under the write lock for a change (:func:`~backend.repositories.common.locked`)."""
    return locked(session, Run, run_id, "run")


def stored_has_trajectory(run: Run, has_trajectory: bool) -> None:
    """Set the flushed ``run``'s ``has_trajectory`` (an SQL expression the flush expired) to what is
    known of it: it saves a SELECT of the row just written (a tenth of POST /runs's CPU)."""
    set_committed_value(run, "has_trajectory", has_trajectory)


def relabel(run: Run, tags: list[str]) -> None:
    """Replace a locked run's tags with ``tags``: the ones kept stay rows, the rest are deleted (orphans)."""
    wanted = set(tags)
    kept = [row for row in run.run_tags if row.tag in wanted]
    run.run_tags = kept + [RunTag(tag=tag) for tag in sorted(wanted - {row.tag for row in kept})]


def flushed(session: Session, run: Run) -> None:
    """Flush a change of ``run`` and read back its ``has_trajectory`` (an SQL expression the flush
    expired) inside the transaction: after the commit a concurrent delete may have removed the row
    it would be read from."""
    session.flush()
    session.refresh(run, ["has_trajectory"])


WHOLE_ORDER_FROM = 500  # [runs] an offset from which a filtered page is cut from the whole order, kept


def listed_page(
    session: Session, where: RunFilter, *, limit: int, cursor: int | None, sort: str = "-id", offset: int = 0
) -> tuple[list[dict], int | None, int]:
    """A page of listed runs (dicts of :data:`LISTED` and ``tags``), what fetches the next, and
    how many runs match in all (:func:`matching_count`). Sorted by id (newest first by default)
    the next is a keyset ``cursor`` (the last id of this page; a page asked for by ``offset``
    instead gives one too); by another column (``-climb``: best first) the next ``offset``. None
    at the end. Rows that tie on the sorted column are in id order, so pages never overlap.

    Every sort has an index (id's own too, ``ix_runs_id``: SQLite's table is no narrow order), so
    an unfiltered page at any offset reads an index and its rows: 1-5 ms at 100,000 runs. A
    filtered page needs the matching runs sorted; on SQLite it is cut from their whole order,
    read once and kept on the connection until a run other than the newest changes
    (:func:`~backend.repositories.run_list_cache.kept_order` puts the runs since in):
    :class:`~backend.repositories.run_list_cache.ListCache`. Sorting the runs of one kind by date
    reads 25,000 rows (70 ms), every page after that its 50 (1-2 ms). A first page (``offset``
    below :data:`WHOLE_ORDER_FROM`) is read by itself the first time its order is asked for after
    a write, and the order read whole only when asked again before the next write: every write
    drops what was kept, and reading a whole order for each first page after a write halved the
    throughput of a mix with 20% writes."""
    if sort not in SORTS:
        raise ValueError(f"sort must be one of {', '.join(SORTS)}, got {sort!r}")
    by_id = sort.lstrip("-") == "id"
    values = bound_values(where)
    connection = session.connection()
    cache = None if by_id and cursor is not None else list_cache(connection)
    key = (tuple(values.items()), sort)
    ids = None if cache is None else kept_order(connection, cache, key, values)
    if ids is None and cache is not None and values and (offset >= WHOLE_ORDER_FROM or cache.asked_again(key)):
        ids = array("q", connection.execute(_ids_statement(sort, tuple(values)), values).scalars())
        cache.keep_order(key, ids, cache.stamp.newest)
        cache.keep_count(key[0], len(ids))
    if ids is not None:
        rows = _rows_of(connection, ids[offset : offset + limit + 1], sort)
    else:
        rows = _page_rows(connection, values, limit=limit, cursor=cursor, sort=sort, offset=offset)
    more = len(rows) > limit
    rows = rows[:limit]
    total = len(ids) if ids is not None else matching_count(session, where)
    if by_id:
        return rows, rows[-1]["id"] if more else None, total
    return rows, offset + limit if more else None, total


def _page_rows(connection, values: dict, *, limit: int, cursor: int | None, sort: str, offset: int) -> list[dict]:
    """The page's rows (``limit + 1`` at most) read in one query: by keyset ``cursor`` (id sorts) or ``offset``."""
    keyset = sort.lstrip("-") == "id" and cursor is not None
    statement = _page_statement(sort, tuple(values), keyset)
    values = values | {"page_rows": limit + 1} | ({"cursor": cursor} if keyset else {"page_offset": offset})
    return _listed_rows(connection.execute(statement, values))


def _rows_of(connection, ids: array, sort: str) -> list[dict]:
    """The listed rows of ``ids``, in ``sort`` order."""
    if not ids:
        return []
    return _listed_rows(connection.execute(_rows_statement(sort), {"ids": list(ids)}))


def _listed_rows(result) -> list[dict]:
    """Plain Core rows as listed dicts: JSON columns decoded in one call, tags split and sorted."""
    rows = [dict(row) for row in result.mappings()]
    decoded = decode_json_texts([[row[name] for name in LISTED_JSON] for row in rows])
    for row, json_values in zip(rows, decoded, strict=True):
        row.update(zip(LISTED_JSON, json_values, strict=True))
        tag_list = row.pop("tag_list")
        row["tags"] = sorted(tag_list.split(TAG_SEPARATOR)) if tag_list else []
    return rows


def _sort_order(sort: str) -> list:
    """ORDER BY for ``sort``: the column, then id the same way. Nulls sort as the smallest value
    on every database (SQLite's own order: PostgreSQL is told so)."""
    name = sort.lstrip("-")
    column = getattr(Run, name)
    if sort.startswith("-"):
        first = column.desc().nulls_last() if name in NULLABLE_SORTS else column.desc()
        return [first, Run.id.desc()] if name != "id" else [first]
    first = column.asc().nulls_first() if name in NULLABLE_SORTS else column.asc()
    return [first, Run.id.asc()] if name != "id" else [first]


@functools.lru_cache(maxsize=512)
def _ids_statement(sort: str, criteria: tuple[str, ...]) -> Select:
    """Every matching id in ``sort`` order (bindparams named as the criteria)."""
    return where_criteria(select(Run.id), criteria).order_by(*_sort_order(sort))


@functools.lru_cache(maxsize=64)
def _rows_statement(sort: str) -> Select:
    """The listed rows of the ids bound as ``ids``, in ``sort`` order."""
    return select(*LISTED, _TAG_LIST).where(Run.id.in_(bindparam("ids", expanding=True))).order_by(*_sort_order(sort))


@functools.lru_cache(maxsize=512)
def _page_statement(sort: str, criteria: tuple[str, ...], keyset: bool) -> Select:
    """The page query for a sort, a set of filter criteria and whether a keyset cursor applies,
    with every value a bindparam: built once per shape, so a page pays neither building the
    statement nor its cache key, only its values (a zeta0-range page of 50 at 20,000 runs: 2.1 → 1.4 ms).

    The page's ids first, then their rows, each with its tags in one column: a filter an index
    cannot order (a zeta0 range sorted by id) sorts only ids, once, not thousands of whole rows;
    and a page is 51 rows stepped, not one per tag (each step hands the GIL to another thread)."""
    order = _sort_order(sort)
    ids = where_criteria(select(Run.id), criteria).order_by(*order).limit(bindparam("page_rows", type_=Integer))
    if keyset:
        descending = sort.startswith("-")
        ids = ids.where(Run.id < bindparam("cursor") if descending else Run.id > bindparam("cursor"))
    else:
        ids = ids.offset(bindparam("page_offset", type_=Integer))
    return select(*LISTED, _TAG_LIST).where(Run.id.in_(ids)).order_by(*order)


def counts_by(session: Session, where: RunFilter, by: str) -> dict:
    """How many matching runs have each value of column ``by`` (None left out), by value."""
    column = getattr(Run, by)
    query = filtered(select(column, func.count()).where(column.is_not(None)).group_by(column), where)
    return {value: runs for value, runs in session.execute(query.order_by(column))}


def value_range(session: Session, where: RunFilter, by: str) -> tuple:
    """The smallest and largest of column ``by`` over the matching runs ((None, None) when none match)."""
    column = getattr(Run, by)
    return tuple(session.execute(filtered(select(func.min(column), func.max(column)), where)).one())


def group_stats(session: Session, where: RunFilter, by: str, bins: tuple[float, float, float, int] | None = None):
    """The matching runs grouped by ``by`` (a column, or ``tag``): each group's ``key``, ``runs``,
    and for climb and jumps completed ``<name>_mean``, ``_mean_square``, ``_min`` and ``_max``,
    all as floats (PostgreSQL averages integers as numeric). ``bins`` = (low, high, width, count):
    groups are then equal bins and ``key`` the bin's index (the last bin includes ``high``)."""
    column = RunTag.tag if by == "tag" else getattr(Run, by)
    key = column
    if bins is not None:
        low, high, width, count = bins
        key = case((column >= high, count - 1), else_=cast((column - low) / width, Integer))
    return session.execute(_grouped(by, column, key, where)).mappings().all()


def group_count(session: Session, where: RunFilter, by: str) -> int:
    """How many distinct values of ``by`` the matching runs have (the groups :func:`group_stats` makes)."""
    column = RunTag.tag if by == "tag" else getattr(Run, by)
    return session.scalar(select(func.count()).select_from(_grouped(by, column, column, where).subquery()))


def _grouped(by: str, column, key, where: RunFilter) -> Select:
    columns = [key.label("key"), func.count(Run.id).label("runs")]
    for name in ("climb", "jumps_completed"):
        value = getattr(Run, name)
        columns += [
            cast(func.avg(value), Float).label(f"{name}_mean"),
            cast(func.avg(value * value), Float).label(f"{name}_mean_square"),
            cast(func.min(value), Float).label(f"{name}_min"),
            cast(func.max(value), Float).label(f"{name}_max"),
        ]
    query = select(*columns)
    query = query.join(RunTag, RunTag.run_id == Run.id) if by == "tag" else query.select_from(Run)
    return filtered(query, where).group_by(key).order_by(key)


def decode_json_texts(rows: list[list[str]]) -> list[list]:
    """Rows of JSON texts (columns read with ``cast(…, Text)``) decoded in one ``json.loads``: a
    page's or a batch's 150 to 3000 small decodes through the column type cost more than its SQL."""
    return json.loads("[" + ",".join("[" + ",".join(texts) + "]" for texts in rows) + "]")


def _tags_where(session: Session, condition) -> dict[int, list[str]]:
    """The tags of the runs ``condition`` selects (on RunTag), by run, sorted (plain Core rows)."""
    tags: dict[int, list[str]] = {}
    query = select(RunTag.run_id, RunTag.tag).where(condition).order_by(RunTag.run_id, RunTag.tag)
    for run_id, tag in session.connection().execute(query):
        tags.setdefault(run_id, []).append(tag)
    return tags


def exported_batch(session: Session, where: RunFilter, columns, after_id: int, last_id: int) -> tuple[list, dict]:
    """The matching runs' ``columns`` (``Run.id`` first) with ids in (``after_id``, ``last_id``],
    oldest first, and their tags by run: one part of an export (:func:`export_part_ends`), never
    all of it in memory. Plain Core rows (no ORM loading); the batch's tags are read by its id
    range, not a thousand parameters."""
    query = filtered(select(*columns).where(Run.id > after_id, Run.id <= last_id), where)
    batch = session.connection().execute(query.order_by(Run.id)).all()
    tags = _tags_where(session, RunTag.run_id.between(batch[0][0], batch[-1][0])) if batch else {}
    return batch, tags


def export_part_ends(session: Session, where: RunFilter) -> list[int]:
    """Where each part of an export of the matching runs ends: the id of every
    :data:`EXPORT_BATCH`-th of them, oldest first, and the newest's (empty when none match). One
    pass over the matching ids; the parts' own reads then need nothing from each other."""
    numbered = filtered(
        select(Run.id, func.row_number().over(order_by=Run.id).label("n"), func.max(Run.id).over().label("newest")),
        where,
    ).subquery()
    ends = (numbered.c.n % EXPORT_BATCH == 0) | (numbered.c.id == numbered.c.newest)
    return list(session.scalars(select(numbered.c.id).where(ends).order_by(numbered.c.id)))


def widest_schedule(session: Session, where: RunFilter, last_id: int) -> int:
    """The most legs any matching run's schedule has, of those with ids up to ``last_id`` (0 when
    none match)."""
    query = filtered(select(func.max(func.json_array_length(Run.controls))).where(Run.id <= last_id), where)
    return session.scalar(query) or 0
