"""Runs as flat records — one value per column: ``model.alpha``, ``leg0.zeta0`` … — exported as CSV
or JSON, streamed in batches, and lined up side by side by compare (``services.runs.compare``).

An export reads plain rows of the columns it writes (never a run's results or trajectory), their
JSON columns as text decoded once per batch of 1000, and writes each batch in one call of the
``csv`` or ``json`` module: about 3x the rows per second of one dict and three ``json.loads``
per run (scripts/bench_export.py).
"""

from __future__ import annotations

import csv
import dataclasses
import functools
import io
import json
from collections.abc import Iterable, Iterator, Sequence
from dataclasses import dataclass

from sqlalchemy.orm import Session

from backend.repositories.runs import (
    EXPORTED,
    JSON_COLUMNS,
    RunFilter,
    decode_json_texts,
    export_part_ends,
    exported_batch,
    widest_schedule,
)
from experiments.manifest import json_safe
from sim_core.model.params import ModelParams

RECORD_FIELDS = ("id", "experiment_id", "kind", "status", "created_at", "duration_s", "code_version", "tags", "notes",
                 "jumps", "jumps_completed", "failure_code", "climb", "start_xdot", "start_ydot", "end_reason",
                 "loop", "controller", "target", "touchdowns")  # fmt: skip
MODEL_FIELDS = tuple(field.name for field in dataclasses.fields(ModelParams))
TEXT_FIELDS = ("kind", "status", "code_version", "tags", "notes", "failure_code", "end_reason", "loop", "controller")
TEXT_COLUMNS = tuple(RECORD_FIELDS.index(name) for name in TEXT_FIELDS)
FORMULA_START = frozenset("=+-@\t\r\n")  # a spreadsheet reads a cell starting with one as a formula
CHUNK_CHARS = 64_000  # what a streamed export yields at a time


@functools.cache
def record_fields(legs: int) -> tuple[str, ...]:
    """The columns of a flat record whose schedule has ``legs`` legs."""
    fields = (*RECORD_FIELDS, *(f"model.{name}" for name in MODEL_FIELDS))
    return fields + tuple(f"leg{leg}.{name}" for leg in range(legs) for name in ("psi0_deg", "zeta0"))


def record_values(run, model: dict, controls: Sequence, start_state: Sequence, tags: Iterable[str], legs: int) -> list:
    """A run's values in :func:`record_fields` order (legs past its own schedule are None). ``run``
    is a stored Run or a row of :data:`EXPORTED`; ``model``, ``controls`` and ``start_state`` its
    decoded JSON columns."""
    values = [run.id, run.experiment_id, run.kind, run.status, run.created_at.isoformat(), run.duration_s,
              run.code_version, " ".join(tags), run.notes, run.jumps, run.jumps_completed, run.failure_code, run.climb,
              start_state[0], start_state[1], run.end_reason, run.loop, run.controller, run.target, run.touchdowns,
              *map(model.get, MODEL_FIELDS)]  # fmt: skip
    for leg in range(legs):
        values += controls[leg] if leg < len(controls) else (None, None)
    return values


def flat_record(run, tags: Iterable[str]) -> dict:
    """A stored run as one flat record: its own legs only."""
    return _record(run, run.model, run.controls, run.start_state, tags)


def _record(run, model: dict, controls: Sequence, start_state: Sequence, tags: Iterable[str]) -> dict:
    """:func:`record_values` as a dict, with the run's own legs."""
    values = record_values(run, model, controls, start_state, tags, len(controls))
    return dict(zip(record_fields(len(controls)), values, strict=True))


@dataclass(frozen=True)
class ExportPlan:
    """What every part of one export shares, fixed at its start: the format, the CSV's legs (as
    many as the widest run: its columns come before the first row), and where each part ends:
    part k holds the matching runs with ids in (``ends[k - 1]``, ``ends[k]``] (from 0), at most
    :data:`backend.repositories.runs.EXPORT_BATCH` of them. Runs stored after the export began are not
    in it; one deleted meanwhile is left out of a part not read yet."""

    format: str
    legs: int
    ends: tuple[int, ...]


def plan_export(session: Session, where: RunFilter, format_: str) -> ExportPlan:
    ends = tuple(export_part_ends(session, where))
    legs = widest_schedule(session, where, ends[-1]) if format_ == "csv" and ends else 0
    return ExportPlan(format_, legs, ends)


def export_head(plan: ExportPlan) -> str:
    return "".join(csv_text([[list(record_fields(plan.legs))]], ())) if plan.format == "csv" else "["


def export_tail(plan: ExportPlan) -> str:
    return "" if plan.format == "csv" else "]"


def export_part(session: Session, where: RunFilter, plan: ExportPlan, part: int) -> str:
    """Part ``part`` of the export as text: CSV rows, or JSON records without the array's brackets
    and commas around them (:func:`joined` puts them in). The parts depend on nothing but the
    plan, so they can be read anywhere, in any order, a short transaction each
    (backend/workers/store_reads.py: in the read workers, two at a time)."""
    after_id = plan.ends[part - 1] if part else 0
    batch, tags = exported_batch(session, where, EXPORTED, after_id, plan.ends[part])
    decoded = decode_json_texts([[getattr(row, name) for name in JSON_COLUMNS] for row in batch])
    runs = [(row, *columns, tags.get(row.id, ())) for row, columns in zip(batch, decoded, strict=True)]
    if plan.format == "csv":
        return "".join(csv_text([[record_values(*run, plan.legs) for run in runs]], TEXT_COLUMNS))
    return json_text([_record(*run) for run in runs])


def joined(plan: ExportPlan, text: str, follows: bool) -> str:
    """A part's ``text`` as it goes into the export: after another part's records (``follows``)
    a JSON part's come after a comma."""
    return "," + text if plan.format == "json" and follows and text else text


def export(sessions, where: RunFilter, format_: str) -> Iterator[str]:
    """Every matching run, oldest first, as CSV or JSON text in parts, each part read in a session
    of its own (the response streams after the request's session has closed). The CSV's columns
    are known before the first row: every model field and as many legs as the widest run; a JSON
    record has its own run's legs."""
    with sessions() as session:
        plan = plan_export(session, where, format_)
    yield export_head(plan)
    follows = False
    for part in range(len(plan.ends)):
        with sessions() as session:
            text = export_part(session, where, plan, part)
        yield joined(plan, text, follows)
        follows = follows or bool(text)
    yield export_tail(plan)


def csv_text(batches: Iterable[list[list]], text_columns=TEXT_COLUMNS) -> Iterator[str]:
    """Batches of rows of values as CSV text in chunks of about :data:`CHUNK_CHARS`. Text that a spreadsheet
    would run as a formula (starting with = + - @, a tab or a line break — or with spaces before
    any of them, which spreadsheets skip) in a ``text_columns`` cell is written with a leading
    apostrophe, as OWASP advises; numbers are written as they are."""
    buffer = io.StringIO()
    writer = csv.writer(buffer)
    for batch in batches:
        for row in batch:
            for column in text_columns:
                value = row[column]
                if value and (value[0] in FORMULA_START or value.lstrip()[:1] in FORMULA_START):
                    row[column] = "'" + value
        writer.writerows(batch)
        if buffer.tell() > CHUNK_CHARS:
            yield buffer.getvalue()
            buffer.seek(0)
            buffer.truncate()
    yield buffer.getvalue()


def json_text(records: list[dict]) -> str:
    """Records as the members of a strict JSON array, without its brackets (NaN and infinities as
    null); no records, no text."""
    try:
        text = json.dumps(records, allow_nan=False)
    except ValueError:  # a NaN or an infinity somewhere in the batch: JSON has neither
        text = json.dumps(json_safe(records))
    return text[1:-1]
