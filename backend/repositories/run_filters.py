"""Which runs a list, an export or an aggregate covers (:class:`RunFilter`), as SQL conditions.

Every criterion reads an index; the search ``q`` the one migration 0012 made (SQLite's FTS5
trigram table ``run_search``, PostgreSQL's trigram indexes). What a connection keeps of the lists
it read (totals, orders) is :mod:`~backend.repositories.run_list_cache`'s.
"""

from __future__ import annotations

import datetime
from dataclasses import dataclass
from typing import ClassVar

from sqlalchemy import Integer, Select, String, bindparam, column, func, literal, literal_column, select, table, union
from sqlalchemy.ext.compiler import compiles
from sqlalchemy.sql.expression import ColumnElement
from sqlalchemy.sql.visitors import InternalTraversal
from sqlalchemy.types import Boolean

from backend.store.models import Run, RunTag

MIN_SEARCH = 3  # characters: a trigram index finds any text of three or more


@dataclass(frozen=True)
class RunFilter:
    """Which runs a list, export or aggregate covers; None leaves a criterion out. Ranges are
    inclusive; ``created_before`` is exclusive. ``end_reason`` matches a reason as stored or every
    reason of its kind ("error" matches "error: …"); ``q`` is text found in a run's notes or in one
    of its tags, case-insensitively, at least :data:`MIN_SEARCH` characters (what an index of
    trigrams finds; a shorter one is a ValueError); ``ids`` keeps only the runs named (a basket)."""

    experiment_id: int | None = None
    world_id: int | None = None
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
    ids: tuple[int, ...] | None = None  # these runs only (a basket)

    def __post_init__(self):
        if self.q is not None and len(self.q) < MIN_SEARCH:
            raise ValueError(f"q: a search needs at least {MIN_SEARCH} characters, got {self.q!r}")


def _sql_text(value: str):
    """A constant string written into the statement, not bound: the two spellings of a search
    (:class:`_PerDialect`) then bind one parameter alike, the text searched for."""
    return literal_column("'" + value.replace("'", "''") + "'", String)


def _containing(text):
    """A LIKE pattern (escaped with ``\\``) for values that contain ``text`` (an SQL expression)."""
    escaped = text
    for special in ("\\", "%", "_"):
        escaped = func.replace(escaped, _sql_text(special), _sql_text("\\" + special), type_=String)
    return _sql_text("%") + escaped + _sql_text("%")


def _same_or_kind_of(v):
    # "error" matches "error" and "error: …": a range over the index, not a LIKE (which SQLite's
    # case-insensitive LIKE cannot read from an index).
    return (Run.end_reason == v) | ((Run.end_reason >= v + ":") & (Run.end_reason < v + ";"))


def _tagged(tag, runs_tagged=None):
    return (runs_tagged or _among_tagged)(RunTag.tag == tag)


_RUN_SEARCH = table("run_search", column("rowid"), column("run_search"))  # migration 0012's FTS5 table


class _PerDialect(ColumnElement):
    """A condition written one way for SQLite and another for the other databases."""

    type = Boolean()
    inherit_cache = True
    _is_implicitly_boolean = True  # a condition as it stands (no "= 1" where there is no boolean type)
    _traverse_internals: ClassVar = [("sqlite", InternalTraversal.dp_clauseelement),
                                     ("other", InternalTraversal.dp_clauseelement)]  # fmt: skip

    def __init__(self, sqlite, other):
        self.sqlite, self.other = sqlite, other


# In parentheses: the statement around it cannot see inside (an OR beside an AND would bind wrong).
@compiles(_PerDialect)
def _other(element, compiler, **kw):
    return f"({compiler.process(element.other, **kw)})"


@compiles(_PerDialect, "sqlite")
def _sqlite(element, compiler, **kw):
    return f"({compiler.process(element.sqlite, **kw)})"


def _search(text, since=None):
    """Runs whose notes or one of whose tags contain ``text`` (a value or a bindparam), in any case
    (``since``: of the runs from that id on). SQLite: a phrase query of the trigram FTS table (the
    text quoted, so it is never read as FTS syntax); PostgreSQL: ``ILIKE`` (its trigram indexes
    read it), the text's wildcards escaped."""
    if not isinstance(text, ColumnElement):
        text = literal(text, String)  # one parameter, shared by both spellings
    phrase = _sql_text('"') + func.replace(text, _sql_text('"'), _sql_text('""'), type_=String) + _sql_text('"')
    found = select(_RUN_SEARCH.c.rowid).where(_RUN_SEARCH.c.run_search.op("MATCH")(phrase))
    indexed = Run.id.in_(found if since is None else found.where(_RUN_SEARCH.c.rowid >= since))
    # One list of ids from both indexes (a UNION): PostgreSQL reads neither through an index
    # where the notes' ILIKE and the tags' are ORed in one condition (it scanned every run).
    pattern = _containing(text)
    in_notes = select(Run.id).where(Run.notes.ilike(pattern, escape="\\"))
    in_tags = select(RunTag.run_id).where(RunTag.tag.ilike(pattern, escape="\\"))
    if since is not None:
        in_notes, in_tags = in_notes.where(Run.id >= since), in_tags.where(RunTag.run_id >= since)
    return _PerDialect(indexed, Run.id.in_(union(in_notes, in_tags)))


# How a condition on the tags becomes one on the runs: the list of the runs tagged (the tags'
# index, then each run by its id: a rare tag is a few lookups, whatever the sort), or for a count
# of the newest runs only the part of that list from an id on.
def _among_tagged(condition):
    return Run.id.in_(select(RunTag.run_id).where(condition))


def _among_tagged_since(since):
    return lambda condition: Run.id.in_(select(RunTag.run_id).where(condition, RunTag.run_id >= since))


# Each filter criterion as the condition it puts on a query, given its value (a literal, or a
# bindparam in a cached page statement; see _BOUND for the values a criterion binds). Every
# criterion reads an index.
_CONDITIONS = {
    "experiment_id": lambda v: Run.experiment_id == v,
    "world_id": lambda v: Run.world_id == v,
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
    "tag": _tagged,
    "q": _search,
    "ids": lambda v: Run.id.in_(v),
}
_READ_TAGS = frozenset({"tag"})  # the criteria that read run_tags: they take how (runs_tagged) too
_BOUND: dict = {}  # a criterion's value as its condition takes it, where not as given
_TYPED = {"end_reason": String, "q": String}  # bindparams whose type a concatenation or LIKE needs
_EXPANDING = frozenset({"ids"})  # bindparams of a list of values (IN)


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


def where_criteria(query: Select, criteria: tuple[str, ...], *, since: bool = False) -> Select:
    """``query`` with the conditions of ``criteria``, each value a bindparam named as its criterion.
    ``since``: only the runs from the id bound as ``since`` on, read through the id's range (and
    the tags' from that id) even where an index of a criterion would serve a whole count better:
    the newest runs, counted again after a write (:mod:`~backend.repositories.run_list_cache`;
    SQLite only: it reads ``likelihood``, which PostgreSQL has not)."""
    first_id = bindparam("since", type_=Integer) if since else None
    runs_tagged = _among_tagged_since(first_id) if since else _among_tagged
    for criterion in criteria:
        value = bindparam(criterion, type_=_TYPED.get(criterion), expanding=criterion in _EXPANDING)
        if criterion == "q":
            query = query.where(_search(value, since=first_id))
        elif criterion in _READ_TAGS:
            query = query.where(_CONDITIONS[criterion](value, runs_tagged))
        else:
            query = query.where(_CONDITIONS[criterion](value))
    if since:
        # SQLite's planner takes an index of the criterion (zeta0 >= ?: every run in the range)
        # over the id range unless told that few runs pass it.
        query = query.where(func.likelihood(Run.id >= first_id, literal_column("0.001")))
    return query
