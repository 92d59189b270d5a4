"""Runs as flat records — one value per column: ``model.alpha``, ``leg0.zeta0`` … — exported as CSV
or JSON, streamed in batches, and lined up side by side by compare (``records.compare_runs``).

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

from sqlalchemy import Text, cast
from sqlalchemy.orm import Session

from backend.store.models import Run
from backend.store.runs import RunFilter, decode_json_texts, exported_rows, widest_schedule
from experiments.manifest import json_safe
from sim_core.params import ModelParams

RECORD_FIELDS = ("id", "experiment_id", "kind", "status", "created_at", "duration_s", "code_version", "tags", "notes",
                 "jumps", "jumps_completed", "failure_code", "climb", "start_xdot", "start_ydot")  # fmt: skip
MODEL_FIELDS = tuple(field.name for field in dataclasses.fields(ModelParams))
TEXT_COLUMNS = tuple(RECORD_FIELDS.index(name) for name in ("kind", "status", "code_version", "tags", "notes",
                                                           "failure_code"))  # fmt: skip
FORMULA_START = frozenset("=+-@\t\r")  # a spreadsheet reads a cell starting with one as a formula
CHUNK_CHARS = 64_000  # what a streamed export yields at a time
JSON_COLUMNS = ("model", "controls", "start_state")
# What an export reads of each run: the record's own columns, then its JSON columns as text.
EXPORTED = (Run.id, Run.experiment_id, Run.kind, Run.status, Run.created_at, Run.duration_s, Run.code_version,
            Run.notes, Run.jumps, Run.jumps_completed, Run.failure_code, Run.climb,
            *(cast(getattr(Run, name), Text).label(name) for name in JSON_COLUMNS))  # fmt: skip


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
              start_state[0], start_state[1], *[model.get(name) for name in MODEL_FIELDS]]  # fmt: skip
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


def export(sessions, where: RunFilter, format_: str) -> Iterator[str]:
    """Every matching run, oldest first, as CSV or JSON text in chunks, read in batches in a
    session of its own (the response streams after the request's session has closed). The CSV's
    columns are known before the first row: every model field and as many legs as the widest run;
    a JSON record has its own run's legs."""
    with sessions() as session:
        if format_ == "csv":
            legs = widest_schedule(session, where)
            yield from csv_text(_values(session, where, legs), record_fields(legs))
        else:
            yield from json_text(_records(session, where))


def _decoded_batches(session: Session, where: RunFilter):
    """Batches of (row, model, controls, start_state, tags) — a batch's JSON decoded in one call."""
    for batch, tags in exported_rows(session, where, EXPORTED):
        decoded = decode_json_texts([[getattr(row, name) for name in JSON_COLUMNS] for row in batch])
        yield [(row, *columns, tags.get(row.id, ())) for row, columns in zip(batch, decoded, strict=True)]


def _values(session: Session, where: RunFilter, legs: int) -> Iterator[list[list]]:
    for batch in _decoded_batches(session, where):
        yield [record_values(row, model, controls, start, tags, legs) for row, model, controls, start, tags in batch]


def _records(session: Session, where: RunFilter) -> Iterator[list[dict]]:
    for batch in _decoded_batches(session, where):
        yield [_record(row, model, controls, start, tags) for row, model, controls, start, tags in batch]


def csv_text(batches: Iterable[list[list]], fields: Sequence[str], text_columns=TEXT_COLUMNS) -> Iterator[str]:
    """Batches of rows (values in ``fields`` order) as CSV text in chunks. Text that a spreadsheet
    would run as a formula (starting with = + - @, a tab or a return) in a ``text_columns`` cell is
    written with a leading apostrophe, as OWASP advises; numbers are written as they are."""
    buffer = io.StringIO()
    writer = csv.writer(buffer)
    writer.writerow(fields)
    for rows in batches:
        for row in rows:
            for column in text_columns:
                value = row[column]
                if value and value[0] in FORMULA_START:
                    row[column] = "'" + value
        writer.writerows(rows)
        if buffer.tell() > CHUNK_CHARS:
            yield buffer.getvalue()
            buffer.seek(0)
            buffer.truncate()
    yield buffer.getvalue()


def json_text(batches: Iterable[list[dict]]) -> Iterator[str]:
    """Batches of records as one strict JSON array, a batch at a time (NaN and infinities as null)."""
    yield "["
    first = True
    for records in batches:
        if not records:
            continue
        try:
            text = json.dumps(records, allow_nan=False)
        except ValueError:  # a NaN or an infinity somewhere in the batch: JSON has neither
            text = json.dumps(json_safe(records))
        yield ("" if first else ",") + text[1:-1]
        first = False
    yield "]"
