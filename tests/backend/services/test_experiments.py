"""The experiments service called directly: create, read, edit, delete, pages."""

import pytest

from backend.errors import Conflict, NotFound
from backend.jobs.mjtf import MJTFJobCreate
from backend.repositories import experiments as stored_experiments
from backend.schemas import ExperimentCreate, ExperimentUpdate
from backend.services import experiments, runs
from backend.services.jobs import create_job


def _items(page) -> tuple[list, int | None]:
    return page.items, page.next_cursor


def _all_pages(fetch, limit: int) -> list[list[int]]:
    """Follow ``next_cursor`` from the first page to the last: the ids of each page."""
    pages, cursor = [], None
    while True:
        rows, cursor = fetch(limit=limit, cursor=cursor)
        pages.append([row.id for row in rows])
        if cursor is None:
            return pages


def test_experiment_lifecycle(session):
    experiment = experiments.create(session, ExperimentCreate(name="gaits", tags=["paper"]))
    assert experiments.get(session, experiment.id).name == "gaits"
    assert stored_experiments.run_count(session, experiment.id) == 0
    updated = experiments.update(session, experiment.id, ExperimentUpdate(notes="period 2 next"))
    assert (updated.name, updated.notes, updated.tags) == ("gaits", "period 2 next", ["paper"]), "unset fields stay"
    experiments.delete(session, experiment.id)
    with pytest.raises(NotFound, match=f"experiment {experiment.id} does not exist"):
        experiments.get(session, experiment.id)
    with pytest.raises(NotFound):
        experiments.update(session, experiment.id, ExperimentUpdate(name="again"))


def test_an_experiment_with_runs_is_not_deleted(session, make_run):
    experiment = experiments.create(session, ExperimentCreate(name="busy"))
    run = make_run(experiment_id=experiment.id)
    assert stored_experiments.run_count(session, experiment.id) == 1
    with pytest.raises(Conflict, match="still has runs"):
        experiments.delete(session, experiment.id)
    runs.delete(session, run.id)
    experiments.delete(session, experiment.id)


def test_an_experiment_with_jobs_is_not_deleted(session):
    """Its jobs are its record (the foreign key restricts; it used to surface as an IntegrityError)."""
    experiment = experiments.create(session, ExperimentCreate(name="studies"))
    create_job(session, MJTFJobCreate(experiment_id=experiment.id, zeta0s=[0.9], trials=2))
    with pytest.raises(Conflict, match="has jobs"):
        experiments.delete(session, experiment.id)
    assert experiments.get(session, experiment.id).name == "studies"


def test_experiments_page_newest_first(session):
    made = [experiments.create(session, ExperimentCreate(name=f"e{i}")).id for i in range(5)]
    pages = _all_pages(lambda **page: _items(experiments.list_page(session, **page)), limit=2)
    assert pages == [made[:2:-1], made[2:0:-1], made[:1]]
