"""backend/services/exports.py: runs as flat records, exported as CSV and JSON."""

import csv
import io
import json
import math

import pytest

from backend.repositories import runs as run_store
from backend.repositories import runs as store_runs
from backend.repositories.runs import RunFilter
from backend.schemas import LegIn
from backend.services import exports, runs
from experiments.manifest import json_safe
from sim_core.model.presets import get_preset


def _flat(run) -> dict:
    return exports.flat_record(run, run.tags)


def test_flat_record_flattens_model_and_legs(make_run):
    run = make_run(zeta0=0.9, tags=["b", "a"])
    row = exports.flat_record(run, run.tags)
    assert row["id"] == run.id and row["tags"] == "a b" and row["climb"] == run.climb
    assert (row["leg0.psi0_deg"], row["leg0.zeta0"]) == (30.0, 0.9) and "leg1.zeta0" not in row
    assert row["model.alpha"] == pytest.approx(get_preset("paper").to_model().alpha)
    assert (row["start_xdot"], row["start_ydot"]) == (-0.93, -0.17)
    assert row["created_at"] == run.created_at.isoformat()


def _exported(sessions, where: RunFilter, format_: str = "json"):
    text = "".join(exports.export(sessions, where, format_))
    return json.loads(text) if format_ == "json" else list(csv.DictReader(io.StringIO(text)))


def test_export_reads_matching_runs_oldest_first_in_its_own_session(sessions, stored_runs):
    _, runs = stored_runs
    rows = _exported(sessions, RunFilter(psi0_max=45.0))
    assert [row["id"] for row in rows] == sorted(runs[z].id for z in (0.86, 0.88, 0.9, 0.92, 0.94))
    assert [row["leg0.zeta0"] for row in rows] == [0.86, 0.88, 0.9, 0.92, 0.94]


def test_an_exported_record_is_the_runs_flat_record(sessions, stored_runs, session):
    _, runs = stored_runs
    exported = {row["id"]: row for row in _exported(sessions, RunFilter())}
    for run in runs.values():
        assert exported[run.id] == json.loads(json.dumps(json_safe(_flat(run_store.get_run(session, run.id)))))


def test_csv_export_parses_back(sessions, stored_runs):
    rows = _exported(sessions, RunFilter())
    parsed = _exported(sessions, RunFilter(), "csv")
    assert [int(row["id"]) for row in parsed] == [row["id"] for row in rows]
    assert [float(row["climb"]) for row in parsed] == [row["climb"] for row in rows]
    assert parsed[-1]["failure_code"] == "slip" and parsed[0]["failure_code"] == ""


def test_csv_text_comes_in_pieces():
    batches = [[["id", "text"]]] + [[[i, "x" * 100] for i in range(start, start + 1000)] for start in (0, 1000)]
    pieces = list(exports.csv_text(iter(batches), text_columns=(1,)))
    assert len(pieces) > 2, "a large batch is written in pieces, not one string"
    parsed = list(csv.DictReader(io.StringIO("".join(pieces))))
    assert len(parsed) == 2000 and parsed[-1] == {"id": "1999", "text": "x" * 100}


def test_an_export_with_no_runs_is_the_header_alone_or_an_empty_array(sessions):
    fields = ",".join(exports.record_fields(0))
    assert "".join(exports.export(sessions, RunFilter(), "csv")) == fields + "\r\n"
    assert "".join(exports.export(sessions, RunFilter(), "json")) == "[]"


def test_an_export_reads_a_part_at_a_time_and_ends_at_the_runs_it_began_with(sessions, make_run, monkeypatch):
    """Each part a batch in a session of its own: a run stored during the export is not in it (its
    CSV columns were fixed by the runs there at the start), one deleted before its part is read is
    left out, and the JSON stays one array whatever parts came out empty."""
    monkeypatch.setattr(store_runs, "EXPORT_BATCH", 2)
    ids = [make_run(zeta0=0.86 + 0.01 * k).id for k in range(5)]
    chunks = exports.export(sessions, RunFilter(), "json")
    head, first = next(chunks), next(chunks)
    assert head == "[" and [row["id"] for row in json.loads(f"[{first}]")] == ids[:2]
    two_legs = [LegIn(psi0_deg=30.0, zeta0=0.87), LegIn(psi0_deg=30.0, zeta0=0.9)]
    make_run(controls=two_legs)  # stored while the export streams
    with sessions() as session:
        for run_id in ids[2:4]:  # the whole second part
            runs.delete(session, run_id)
    assert [row["id"] for row in json.loads(head + first + "".join(chunks))] == [*ids[:2], ids[4]]
    parts = list(exports.export(sessions, RunFilter(zeta0_max=0.95), "csv"))
    assert len(parts) == 1 + 2 + 1, "the header, two parts of at most two runs, the (empty) tail"
    assert len(list(csv.reader(io.StringIO("".join(parts))))) == 1 + 4


def test_the_parts_of_an_export_end_at_every_batch_and_at_the_newest_run(session, make_run, monkeypatch):
    monkeypatch.setattr(store_runs, "EXPORT_BATCH", 2)
    ids = [make_run(zeta0=zeta0).id for zeta0 in (0.86, 0.88, 0.9, 0.92, 0.94)]
    assert store_runs.export_part_ends(session, RunFilter()) == [ids[1], ids[3], ids[4]]
    assert store_runs.export_part_ends(session, RunFilter(zeta0_max=0.9)) == [ids[1], ids[2]]
    assert store_runs.export_part_ends(session, RunFilter(zeta0_min=0.89, zeta0_max=0.93)) == [ids[3]]
    assert store_runs.export_part_ends(session, RunFilter(tag="nobody")) == []


def test_csv_export_keeps_every_runs_legs(sessions, make_run):
    """The columns are known before the first row: as many legs as the widest run (a two-leg run
    exported after a one-leg run lost its leg1.* controls when the first row decided)."""
    make_run()
    make_run(controls=[LegIn(psi0_deg=30.0, zeta0=0.87), LegIn(psi0_deg=30.0, zeta0=0.9)])
    parsed = _exported(sessions, RunFilter(), "csv")
    assert parsed[1]["leg1.zeta0"] == "0.9" and parsed[0]["leg1.zeta0"] == ""


@pytest.mark.parametrize(
    "text",
    ['=HYPERLINK("http://x")', "+1+1", "-2+3", "@SUM(A1)", "\tx", "\rx", "\n=1+1", "  =1+1", " \n @SUM(A1)"],
)
def test_csv_cells_a_spreadsheet_would_run_are_escaped(sessions, make_run, session, text):
    runs.update(session, make_run().id, notes=text)
    (row,) = _exported(sessions, RunFilter(), "csv")
    assert row["notes"] == "'" + text and float(row["start_xdot"]) == -0.93, "numbers, negative ones too, as they are"


@pytest.mark.parametrize("text", ["a = b", " plain note", "3 jumps"])
def test_csv_text_that_is_no_formula_is_kept_as_it_is(sessions, make_run, session, text):
    runs.update(session, make_run().id, notes=text)
    (row,) = _exported(sessions, RunFilter(), "csv")
    assert row["notes"] == text


def test_json_export_is_strict_json():
    text = "[" + exports.json_text([{"id": 1, "climb": math.nan, "mu": math.inf}, {"id": 2, "climb": 1.5}]) + "]"
    assert json.loads(text) == [{"id": 1, "climb": None, "mu": None}, {"id": 2, "climb": 1.5}]
    assert json.loads(text, parse_constant=pytest.fail) is not None, "no NaN or Infinity literals"
    assert exports.json_text([]) == ""
