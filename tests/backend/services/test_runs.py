"""The runs service called directly: store, read, edit, delete, filters, pages, comparison, groups."""

import math

import pytest

from backend.errors import NotFound
from backend.repositories import runs as run_store
from backend.repositories.common import locked
from backend.repositories.runs import RunFilter
from backend.services import runs
from backend.store.models import Run
from sim_core import ControlSchedule, iterate_map
from tests.backend.services.bodies import START

CLIMB_RTOL = 1e-12  # a stored climb is the sum of the map's rises, rounded once more


def _ids(rows) -> list[int]:
    """Listed runs are plain rows (dicts); other lists are stored records."""
    return [row["id"] if isinstance(row, dict) else row.id for row in rows]


def _all_pages(fetch, limit: int) -> list[list[int]]:
    """Follow ``next_cursor`` from the first page to the last: the ids of each page."""
    pages, cursor = [], None
    while True:
        rows, cursor, _total = fetch(limit=limit, cursor=cursor)
        pages.append(_ids(rows))
        if cursor is None:
            return pages


def test_a_run_stores_what_the_map_computes(session, make_run, paper):
    run = make_run(zeta0=0.9, tags=["b", "a", "b"])
    orbit = iterate_map(paper, ControlSchedule.from_degrees([(30.0, 0.9)]), (START.xdot, START.ydot), 4)
    assert (run.kind, run.status, run.jumps, run.jumps_completed, run.failure_code) == ("sim", "done", 4, 4, None)
    assert run.climb == pytest.approx(float(orbit.rises.sum()), rel=CLIMB_RTOL)
    assert run.results["states"] == orbit.states.tolist()
    assert run.tags == ["a", "b"], "tags are a sorted set"
    assert (run.controls, run.start_state, run.zeta0, run.psi0_deg) == ([[30.0, 0.9]], [-0.93, -0.17], 0.9, 30.0)
    assert run.trajectory is None and run.notes == ""
    assert runs.get(session, run.id).climb == run.climb


def test_a_physical_failure_is_a_done_run_with_its_code(make_run):
    run = make_run(psi0_deg=60.0)  # slips at once
    assert (run.status, run.failure_code, run.jumps_completed, run.climb) == ("done", "slip", 0, 0.0)


def test_a_run_in_a_missing_experiment_is_not_stored(session, make_run):
    with pytest.raises(NotFound, match="experiment 999"):
        make_run(experiment_id=999)
    assert runs.list_runs(session, RunFilter(), limit=10, cursor=None) == ([], None, 0)


def test_update_and_delete_a_run(session, make_run):
    run = make_run(tags=["first"])
    runs.update(session, run.id, notes="left foot slipped")
    assert (run.tags, run.notes) == (["first"], "left foot slipped"), "tags left out stay"
    runs.update(session, run.id, tags=["keep", "best", "keep"])
    assert (run.tags, run.notes) == (["best", "keep"], "left foot slipped"), "notes left out stay"
    runs.update(session, run.id, tags=[])
    assert run.tags == []
    runs.delete(session, run.id)
    for call in (runs.get, runs.delete, runs.update):
        with pytest.raises(NotFound, match=f"run {run.id}"):
            call(session, run.id)


def test_an_edit_replaces_the_stored_tags_not_the_ones_its_session_read(sessions, make_run):
    """Two sessions, as two requests: the first read the run before the second retagged it. Its
    edit replaces what is stored (read again under the write lock), not its stale copy — which
    used to insert a tag still there (UNIQUE failed) or leave the other edit's tags in place."""
    run = make_run(tags=["a", "b"])
    with sessions() as first, sessions() as second:
        stale = run_store.get_run(first, run.id)  # held: the session keeps its copy
        assert stale.tags == ["a", "b"]
        runs.update(second, run.id, tags=["c", "d"], notes="second")
        assert runs.update(first, run.id, tags=["a", "c"]).tags == ["a", "c"]
        assert (stale.tags, stale.notes) == (["a", "c"], "second")
    with sessions() as fresh:
        stored = run_store.get_run(fresh, run.id)
        assert (stored.tags, stored.notes) == (["a", "c"], "second")


def test_an_edit_waits_for_the_write_lock_and_reads_after_it(sessions, make_run):
    """While another transaction holds the write lock, an edit does not read: it waits, then sees
    that transaction's commit (here: the run deleted, so a 404 rather than tags for a missing run)."""
    import threading

    run = make_run(tags=["a"])
    outcome = []
    with sessions() as holder:
        locked(holder, Run, run.id, "run")
        holder.delete(holder.get(Run, run.id))
        holder.flush()

        def edit():
            with sessions() as editor:
                try:
                    runs.update(editor, run.id, tags=["b"])
                    outcome.append("updated")
                except NotFound:
                    outcome.append("not found")

        editor = threading.Thread(target=edit)
        editor.start()
        editor.join(0.5)
        assert editor.is_alive(), "the edit waits for the lock"
        holder.commit()
    editor.join(10)
    assert outcome == ["not found"]


@pytest.mark.parametrize(
    ("where", "expected"),
    [
        (RunFilter(), [0.86, 0.88, 0.9, 0.92, 0.94, "slip"]),
        (RunFilter(tag="middle"), [0.9, "slip"]),
        (RunFilter(failure_code="slip"), ["slip"]),
        (RunFilter(zeta0_min=0.88, zeta0_max=0.92, psi0_max=45.0), [0.88, 0.9, 0.92]),
        (RunFilter(psi0_min=45.0), ["slip"]),
        (RunFilter(kind="robot"), []),
        (RunFilter(tag="middle", failure_code="slip"), ["slip"]),
    ],
)
def test_filters_select_runs(session, stored_runs, where, expected):
    _, stored = stored_runs
    rows, cursor, total = runs.list_runs(session, where, limit=50, cursor=None)
    assert sorted(_ids(rows)) == sorted(stored[key].id for key in expected) and cursor is None
    assert total == len(expected)


def test_filter_by_experiment_and_creation_time(session, stored_runs):
    experiment, stored = stored_runs
    rows, _, _ = runs.list_runs(session, RunFilter(experiment_id=experiment.id), limit=50, cursor=None)
    assert _ids(rows) == [stored[0.9].id]
    after = stored[0.92].created_at
    rows, _, _ = runs.list_runs(session, RunFilter(created_after=after), limit=50, cursor=None)
    assert set(_ids(rows)) >= {stored[0.92].id, stored[0.94].id, stored["slip"].id} and stored[0.86].id not in _ids(
        rows
    )
    rows, _, _ = runs.list_runs(session, RunFilter(created_before=after), limit=50, cursor=None)
    assert stored[0.92].id not in _ids(rows), "created_before is exclusive"


def test_keyset_pages_cover_every_run_once(session, stored_runs):
    _, stored = stored_runs
    newest_first = sorted((run.id for run in stored.values()), reverse=True)
    pages = _all_pages(lambda **page: runs.list_runs(session, RunFilter(), **page), limit=4)
    assert pages == [newest_first[:4], newest_first[4:]]
    ascending = _all_pages(lambda **page: runs.list_runs(session, RunFilter(), sort="id", **page), limit=4)
    assert ascending == [newest_first[::-1][:4], newest_first[::-1][4:]]


def test_other_orders_page_by_offset(session, stored_runs):
    first, next_offset, total = runs.list_runs(session, RunFilter(), limit=4, cursor=None, sort="-climb")
    climbs = [run["climb"] for run in first]
    assert climbs == sorted(climbs, reverse=True) and next_offset == 4 and total == 6
    rest, end, _ = runs.list_runs(session, RunFilter(), limit=4, cursor=None, sort="-climb", offset=next_offset)
    assert len(rest) == 2 and end is None and max(run["climb"] for run in rest) <= climbs[-1]
    by_zeta0, _, _ = runs.list_runs(session, RunFilter(psi0_max=45.0), limit=10, cursor=None, sort="zeta0")
    assert [run["controls"][0][1] for run in by_zeta0] == [0.86, 0.88, 0.9, 0.92, 0.94]


def test_compare_lines_runs_up_and_can_show_only_differences(session, stored_runs):
    _, stored = stored_runs
    ids = [stored[0.88].id, stored[0.9].id]
    everything = runs.compare(session, ids, only_differences=False).model_dump()
    assert [run["id"] for run in everything["runs"]] == ids and "model.alpha" in everything["fields"]
    assert {"id", "leg0.zeta0", "climb", "tags", "experiment_id"} <= set(everything["differing"])
    assert "model.alpha" not in everything["differing"] and "jumps" not in everything["differing"]
    only = runs.compare(session, ids, only_differences=True).model_dump()
    assert only["fields"][0] == "id" and set(only["fields"]) == set(everything["differing"])
    assert all(set(run) == set(only["fields"]) for run in only["runs"])
    with pytest.raises(NotFound):
        runs.compare(session, [stored[0.9].id, 999], only_differences=True)


def test_aggregate_groups_by_a_column_and_by_tag(session, stored_runs):
    _, stored = stored_runs
    groups = runs.aggregate(session, RunFilter(), "failure_code").model_dump()["groups"]
    by_key = {group["key"]: group for group in groups}
    assert {key: group["runs"] for key, group in by_key.items()} == {None: 5, "slip": 1}
    climbs = [stored[z].climb for z in (0.86, 0.88, 0.9, 0.92, 0.94)]
    mean = sum(climbs) / 5
    climbed = by_key[None]["climb"]
    assert climbed["mean"] == pytest.approx(mean, rel=1e-12)
    assert climbed["std"] == pytest.approx(math.sqrt(sum((c - mean) ** 2 for c in climbs) / 5), rel=1e-6)
    assert (climbed["min"], climbed["max"]) == (min(climbs), max(climbs))
    assert by_key["slip"]["jumps_completed"] == {
        "mean": 0.0, "std": 0.0, "min": 0, "max": 0, "ci95_low": None, "ci95_high": None}  # fmt: skip
    # The mean's 95% interval: Student's t with 4 degrees of freedom on the sample std.
    half_width = 2.7764 * math.sqrt(sum((c - mean) ** 2 for c in climbs) / 4) / math.sqrt(5)
    interval = (climbed["ci95_low"], climbed["ci95_high"])
    assert interval == pytest.approx((mean - half_width, mean + half_width), rel=1e-9)
    tagged = runs.aggregate(session, RunFilter(psi0_max=45.0), "tag").model_dump()["groups"]
    assert [(group["key"], group["runs"]) for group in tagged] == [("middle", 1)]
