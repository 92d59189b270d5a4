"""Mean Jumps To Failure in a stored world as a job (backend/jobs/world_mjtf.py): its trials the
library's on the same seeds, block by block stored, a resumed job's trials the uninterrupted ones."""

import math

import numpy as np
import pytest
from pydantic import ValidationError
from sqlalchemy import delete, update

from backend.jobs.world_mjtf import BLOCK, WorldMjtfJobCreate
from backend.schemas.worlds import WorldCreate
from backend.services import job_runner, jobs, worlds
from backend.store.models import Job, JobChunk
from sim_core import get_preset
from sim_core.model.noise import NoiseModel
from sim_core.planning.launch import start_velocity
from sim_core.robustness.world_trials import REACHED, run_world_trials
from sim_core.world.random_world import random_world
from tests.backend.services.jobs_helpers import WAIT_S, job_now, wait_until

LEGS = [{"psi0_deg": 30.0, "zeta0": 0.9}, {"psi0_deg": 27.5, "zeta0": 0.88}]


def test_the_trials_are_the_librarys_on_the_same_seeds_and_resume_exactly(sessions, session, compute):
    held = worlds.create(session, WorldCreate(name="holds 4", random={"seed": 4}))
    body = WorldMjtfJobCreate(kind="world-mjtf", world_id=held.id, controls=LEGS, trials=BLOCK + 40, cap=150, seed=9,
                              goal_height_m=1.0)  # fmt: skip
    job = jobs.create_job(session, body)
    assert job.total == 2 and job.world_id == held.id
    job_runner.JobRunner(sessions, compute.jobs).run(job.id)
    result = jobs.job_results(session, job.id).result

    model = get_preset("paper").to_model()
    world, metres = random_world(4, width=model.d_hat), get_preset("paper").leg_length
    schedule = np.radians([[leg["psi0_deg"], 0.0] for leg in LEGS]) + [[0.0, leg["zeta0"]] for leg in LEGS]
    jumps, status = run_world_trials(model, schedule, start_velocity(model), NoiseModel(),
                                     9 + np.arange(BLOCK + 40), 150, world, 0.0, 1.0 / metres)  # fmt: skip
    assert result["jumps"] == jumps.tolist() and result["trials"] == BLOCK + 40
    assert result["outcomes"].get("reached", 0) == int(np.count_nonzero(status == REACHED))
    assert result["mean_jumps"] == pytest.approx(float(jumps.mean()), rel=1e-12)
    assert result["std_jumps"] == pytest.approx(float(jumps.std(ddof=1)), rel=1e-12)

    session.execute(delete(JobChunk).where(JobChunk.job_id == job.id, JobChunk.index == 1))
    session.execute(update(Job).where(Job.id == job.id).values(state="running", completed=1, result=None))
    session.commit()
    runner = job_runner.JobRunner(sessions, compute.jobs)
    runner.start()  # as after a kill -9: the job left running, one block stored
    try:
        resumed = wait_until(sessions, job.id, lambda j: j.state in jobs.FINAL)
    finally:
        runner.stop(timeout=WAIT_S)
    assert (resumed.state, resumed.completed) == ("done", 2)
    assert jobs.job_results(session, job.id).result == result


@pytest.mark.parametrize(
    ("changes", "field"),
    [({"controls": []}, "controls"), ({"trials": 0}, "trials"), ({"trials": 100_000, "cap": 100_000}, "over the limit"),
     ({"goal_height_m": math.nan}, "goal_height_m")],
)  # fmt: skip
def test_a_bad_request_is_refused_naming_the_field(changes, field):
    with pytest.raises(ValidationError) as refused:
        WorldMjtfJobCreate(**({"kind": "world-mjtf", "world_id": 1, "controls": LEGS} | changes))
    assert field in str(refused.value)


def test_the_job_shows_its_progress_block_by_block(sessions, session, compute):
    walls = worlds.create(session, WorldCreate(name="walls", named="parallel"))
    job = jobs.create_job(session, WorldMjtfJobCreate(kind="world-mjtf", world_id=walls.id, controls=LEGS[:1],
                                                      trials=3 * BLOCK, cap=20))  # fmt: skip
    job_runner.JobRunner(sessions, compute.jobs).run(job.id)
    done = job_now(sessions, job.id)
    assert (done.state, done.completed, done.total, done.progress) == ("done", 3, 3, 1.0)
