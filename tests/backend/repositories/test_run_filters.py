"""Which runs a filter selects (backend/repositories/run_filters.py): the conditions."""

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
        (RunFilter(q="%"), 1),
    ],
)
def test_each_filter_selects_what_it_says(stored, where, count):
    assert matching_count(stored, where) == count


def test_only_the_criteria_set_are_bound_and_a_search_as_its_pattern():
    assert bound_values(RunFilter()) == {}
    assert bound_values(RunFilter(kind="sim", q="50%_x")) == {"kind": "sim", "q": "%50\\%\\_x%"}
