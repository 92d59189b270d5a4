"""Which runs a filter selects (backend/repositories/run_filters.py): the conditions."""

import re

import pytest

from backend.repositories.run_filters import RunFilter, bound_values
from backend.repositories.run_list_cache import matching_count
from backend.repositories.runs import add_run
from backend.store.run_record import RunRecord


def _record(**changes) -> RunRecord:
    base = {"kind": "robot", "status": "done", "duration_s": 1.0, "code_version": "test", "model": {"alpha": 15.0},
            "controls": [[30.0, 0.9]], "start_state": [-0.93, -0.17], "jumps": 10, "failure_code": None,
            "jumps_completed": 10, "climb": 1.0, "results": {}}  # fmt: skip
    return RunRecord(**(base | changes))


@pytest.fixture
def stored(session):
    for end_reason, notes, tags in [
        ("e-stop", "stopped at the top", ("dry",)),
        ("error: serial port closed", "Slipped on the WET wall", ("wet",)),
        ("error", "", ("50%_grip",)),
        ("link lost", "fine", ()),
        (None, "", ()),
    ]:
        run = add_run(session, _record(results={"end_reason": end_reason}, tags=tags))
        run.notes = notes
    session.commit()
    return session


@pytest.mark.parametrize(
    ("where", "count"),
    [
        (RunFilter(), 5),
        (RunFilter(end_reason="error"), 2),  # "error" and every "error: …"
        (RunFilter(end_reason="error: serial port closed"), 1),
        (RunFilter(end_reason="e"), 0),  # a kind is a whole word before the colon, not a prefix
        (RunFilter(q="wet"), 1),  # notes, in any case
        (RunFilter(q="DRY"), 1),  # a tag, in any case
        (RunFilter(q="50%"), 1),  # LIKE's wildcards are text here
        (RunFilter(q="_grip"), 1),
        (RunFilter(q="%_g"), 1),
        (RunFilter(q='"wet'), 0),  # FTS syntax is text here too
        (RunFilter(q="wet wall"), 1),  # a phrase, not two words
        (RunFilter(q="wall wet"), 0),
        (RunFilter(q="stopped at the top"), 1),
        (RunFilter(q="slipped on the wet"), 1),
        (RunFilter(q="the"), 2),
    ],
)
def test_each_filter_selects_what_it_says(stored, where, count):
    assert matching_count(stored, where) == count


def test_only_the_criteria_set_are_bound():
    assert bound_values(RunFilter()) == {}
    assert bound_values(RunFilter(kind="sim", q="50%_x")) == {"kind": "sim", "q": "50%_x"}


def test_a_search_needs_three_characters():
    with pytest.raises(ValueError, match="at least 3 characters"):
        RunFilter(q="ab")


def test_a_search_reads_the_index_and_follows_every_change(stored):
    """Migration 0012's triggers keep the index: a note rewritten, a tag added or removed, a run
    deleted; and a search is a look-up in it, not a scan of the runs."""
    from sqlalchemy import select, text

    from backend.repositories.run_filters import filtered
    from backend.store.models import Run, RunTag

    run = stored.get(Run, 4)
    run.notes = "now it slipped"
    run.run_tags.append(RunTag(tag="icy"))
    stored.commit()
    assert matching_count(stored, RunFilter(q="slipped")) == 2 and matching_count(stored, RunFilter(q="ICY")) == 1
    run.run_tags.clear()
    run.notes = ""
    stored.commit()
    assert matching_count(stored, RunFilter(q="slipped")) == 1 and matching_count(stored, RunFilter(q="icy")) == 0
    stored.delete(stored.get(Run, 2))
    stored.commit()
    assert matching_count(stored, RunFilter(q="slipped")) == 0
    query = filtered(select(Run.id), RunFilter(q="slipped"))
    statement = query.compile(stored.bind, compile_kwargs={"literal_binds": True})
    plan = " ".join(row[-1] for row in stored.execute(text(f"EXPLAIN QUERY PLAN {statement}")))
    # the index's look-up; the runs only through an index of theirs, never their rows (the notes) one by one
    assert "run_search VIRTUAL TABLE INDEX" in plan and not re.search(r"SCAN runs(?! USING)", plan), plan
    assert "LIKE" not in str(statement), statement
