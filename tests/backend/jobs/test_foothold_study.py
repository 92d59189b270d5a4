"""The foothold study as a job (backend/jobs/foothold_study.py): on a stored world or on random
ones, its result the command's, each world stored as it finishes and a resumed job's result the
uninterrupted one's; its bad requests refused naming the field."""

import pytest
from pydantic import ValidationError
from sqlalchemy import select, update

from backend.errors import NotFound
from backend.jobs import worst_case_jumps
from backend.jobs.foothold_study import FootholdStudyJobCreate
from backend.schemas.job_budget import WORK_BUDGET_JUMPS
from backend.schemas.worlds import WorldCreate
from backend.services import job_runner, jobs, worlds
from backend.store.models import Job, JobChunk
from sim_core.model.errors import ParameterError
from tests.backend.services.jobs_helpers import WAIT_S, job_now, wait_until
from tests.cli.helpers import json_of

TIMINGS = ("plan_seconds_median", "law_us_per_jump")  # measured, not computed: they differ run to run
STUDY = {"kind": "foothold-study", "goal_height_m": 0.5, "trials": 4, "seed": 11}


def without_timings(result: dict) -> dict:
    methods = {
        name: {k: v for k, v in values.items() if k not in TIMINGS} for name, values in result["methods"].items()
    }
    return {**result, "methods": methods}


def run_job(sessions, session, compute, **fields) -> dict:
    job = jobs.create_job(session, FootholdStudyJobCreate(**(STUDY | fields)))
    job_runner.JobRunner(sessions, compute.jobs).run(job.id)
    done = job_now(sessions, job.id)
    assert (done.state, done.completed, done.total) == ("done", done.total, done.total), done.error
    return done


def test_a_study_on_random_worlds_is_the_commands(sessions, session, compute):
    done = run_job(sessions, session, compute, random_worlds={"count": 2, "seed0": 3})
    command = json_of("foothold-study", "--random", "2", "--seed0", "3", "--goal-height", "0.5", "--trials", "4",
                      "--seed", "11")  # fmt: skip
    result = jobs.job_results(session, done.id).result
    assert without_timings(result) == without_timings(command)
    assert [row["world"] for row in result["worlds"]] == ["random:3", "random:4"] and done.world_id is None


def test_a_study_on_a_stored_world_climbs_that_world(sessions, session, compute):
    stored = worlds.create(session, WorldCreate(name="holds 3", random={"seed": 3}))
    done = run_job(sessions, session, compute, world_id=stored.id)
    assert done.world_id == stored.id and done.spec["world"]["left"], "the world copied into the spec"
    on_random = jobs.job_results(
        session, run_job(sessions, session, compute, random_worlds={"count": 1, "seed0": 3}).id
    )
    result = without_timings(jobs.job_results(session, done.id).result)
    expected = without_timings(on_random.result)
    assert result["worlds"][0].pop("world") == "holds 3" and expected["worlds"][0].pop("world") == "random:3"
    assert result == expected, "the stored random world 3 is the study's random world 3"
    assert worlds.get(session, stored.id).jobs == 1, "the world is used by the job on it"


def test_a_resumed_study_computes_only_the_worlds_missing(sessions, session, compute):
    """As after a kill -9: one world's chunk stored, the job left running. The restarted runner
    keeps that chunk (marked here, so a recomputation would show) and computes the others; the
    result is the uninterrupted job's."""
    spec = {"random_worlds": {"count": 3, "seed0": 0}}
    whole = run_job(sessions, session, compute, **spec)
    chunks = session.scalars(select(JobChunk).where(JobChunk.job_id == whole.id).order_by(JobChunk.index)).all()
    assert [chunk.index for chunk in chunks] == [0, 1, 2]

    job = jobs.create_job(session, FootholdStudyJobCreate(**(STUDY | spec)))
    marked = chunks[1].result | {"law_us": 123456.0}
    session.add(JobChunk(job_id=job.id, index=1, result=marked))
    session.execute(update(Job).where(Job.id == job.id).values(state="running", completed=1))
    session.commit()
    runner = job_runner.JobRunner(sessions, compute.jobs)
    runner.start()  # finds the running job and queues it again
    try:
        resumed = wait_until(sessions, job.id, lambda j: j.state in jobs.FINAL)
    finally:
        runner.stop(timeout=WAIT_S)
    assert (resumed.state, resumed.completed, resumed.total) == ("done", 3, 3)
    session.expire_all()
    kept = session.scalar(select(JobChunk.result).where(JobChunk.job_id == job.id, JobChunk.index == 1))
    assert kept == marked, "the stored chunk was not computed again"
    assert without_timings(jobs.job_results(session, job.id).result) == without_timings(
        jobs.job_results(session, whole.id).result
    )


@pytest.mark.parametrize(
    ("changes", "field"),
    [
        ({}, "world_id"),  # neither
        ({"world_id": 1, "random_worlds": {"count": 1}}, "world_id"),  # both
        ({"random_worlds": {"count": 1001}}, "count"),
        ({"random_worlds": {"count": 1}, "trials": 0}, "trials"),
        ({"random_worlds": {"count": 1}, "goal_height_m": -1.0}, "goal_height_m"),
        ({"random_worlds": {"count": 1000}, "trials": 10_000, "cap": 100_000}, "over the limit"),
    ],
)
def test_a_bad_study_is_refused_naming_the_field(changes, field):
    with pytest.raises(ValidationError) as refused:
        FootholdStudyJobCreate(**(STUDY | changes))
    assert field in str(refused.value)


def test_a_goal_out_of_the_world_or_a_world_not_stored_is_refused(session):
    with pytest.raises(ParameterError, match="goal_height_m: must be at most random:5's top"):
        jobs.create_job(
            session,
            FootholdStudyJobCreate(**(STUDY | {"goal_height_m": 50.0, "random_worlds": {"count": 1, "seed0": 5}})),
        )
    with pytest.raises(NotFound, match="world"):
        jobs.create_job(session, FootholdStudyJobCreate(**(STUDY | {"world_id": 999})))
    assert session.scalar(select(Job.id)) is None, "nothing stored"


def test_the_study_is_held_to_the_work_budget():
    jumps, formula = worst_case_jumps(FootholdStudyJobCreate(**(STUDY | {"random_worlds": {"count": 10}})))
    assert 0 < jumps <= WORK_BUDGET_JUMPS and formula.startswith("worlds x")
