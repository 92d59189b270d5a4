"""Reach in a stored world as a job (backend/jobs/reach.py): its result ``parkour reach --json`` on
the stored world written to a file, block of rows by block stored, a resumed job's result the
uninterrupted one's; its bad requests refused naming the field."""

import json

import pytest
from pydantic import ValidationError
from sqlalchemy import delete, select, update

from backend.jobs import decode, encode, spec_of, worst_case_jumps
from backend.jobs import reach as reach_job
from backend.jobs.reach import CHUNK_ROWS, ReachJobCreate
from backend.schemas.worlds import WorldCreate
from backend.services import job_runner, jobs, worlds
from backend.store.models import Job, JobChunk
from sim_core import get_preset
from sim_core.planning.launch import start_velocity
from sim_core.world import reach as sim_reach
from sim_core.world.files import world_from_document
from sim_core.world.reach import grid_values, reach_map
from tests.backend.services.jobs_helpers import WAIT_S, job_now, wait_until
from tests.cli.helpers import json_of

# 3 x 11 cells: two blocks of rows (8 and 3), cells that reach the top and cells that fall
GRID = {"psi0_range": [25.0, 35.0], "psi0_steps": 3, "zeta0_range": [0.86, 0.92], "zeta0_steps": 11, "jumps": 30}
OPTIONS = ("--psi0-range", "25", "35", "--psi0-steps", "3", "--zeta0-range", "0.86", "0.92", "--zeta0-steps", "11",
           "--jumps", "30")  # fmt: skip


def run_job(sessions, session, compute, body: ReachJobCreate):
    job = jobs.create_job(session, body)
    job_runner.JobRunner(sessions, compute.jobs).run(job.id)
    done = job_now(sessions, job.id)
    assert (done.state, done.completed, done.total) == ("done", done.total, done.total), done.error
    return done


def test_the_job_is_the_commands_reach_on_the_same_world_and_resumes_exactly(sessions, session, compute, tmp_path):
    held = worlds.create(session, WorldCreate(name="narrow", named="narrowing"))
    body = ReachJobCreate(kind="reach", world_id=held.id, state={"xdot": -1.0, "ydot": 0.5}, **GRID)
    done = run_job(sessions, session, compute, body)
    assert done.total == 2 and done.world_id == held.id and done.spec["world"]["left"], "the world in the spec"
    result = jobs.job_results(session, done.id).result

    path = tmp_path / "narrow.json"
    path.write_text(json.dumps(done.spec["world"]))  # the stored world's §8 JSON in l0, as the job read it
    command = json_of("reach", "--world", str(path), "--state", "-1.0", "0.5", *OPTIONS)
    assert result == command and result["world"] == "narrow"
    assert result["outcomes"]["top"] > 0 and result["outcomes"]["floor"] > 0, "both endings in the grid"
    assert result["l0_m"] == get_preset("paper").leg_length

    first = select(JobChunk.result).where(JobChunk.job_id == done.id, JobChunk.index == 0)
    marked = session.scalar(first) | {"kept": True}  # a recomputation would drop the mark
    session.execute(update(JobChunk).where(JobChunk.job_id == done.id, JobChunk.index == 0).values(result=marked))
    session.execute(delete(JobChunk).where(JobChunk.job_id == done.id, JobChunk.index == 1))
    session.execute(update(Job).where(Job.id == done.id).values(state="running", completed=1, result=None))
    session.commit()
    runner = job_runner.JobRunner(sessions, compute.jobs)
    runner.start()  # as after a kill -9: the job left running, one block of rows stored
    try:
        resumed = wait_until(sessions, done.id, lambda j: j.state in jobs.FINAL)
    finally:
        runner.stop(timeout=WAIT_S)
    assert (resumed.state, resumed.completed) == ("done", 2)
    session.expire_all()
    assert session.scalar(first) == marked, "the stored block was not computed again"
    assert jobs.job_results(session, done.id).result == result


def test_without_a_state_the_climbs_start_at_the_gaits_velocity(sessions, session, compute):
    held = worlds.create(session, WorldCreate(name="holds 4", random={"seed": 4}))
    grid = {"psi0_steps": 4, "zeta0_steps": 3, "jumps": 12, "foot_y": 0.25}
    done = run_job(sessions, session, compute, ReachJobCreate(kind="reach", world_id=held.id, **grid))
    assert done.total == 1
    model = get_preset("paper").to_model()
    expected = reach_map(model, world_from_document(done.spec["world"]), grid_values(20.0, 40.0, 4),
                         grid_values(0.84, 0.96, 3), start_velocity(model), 12, foot_y=0.25).to_dict()  # fmt: skip
    result = jobs.job_results(session, done.id).result
    assert result == expected | {"l0_m": get_preset("paper").leg_length, "world": "holds 4"}


@pytest.mark.parametrize(
    ("changes", "field", "says"),
    [
        ({"psi0_range": [40.0, 20.0]}, "psi0_range", "low below high, got [40, 20]"),
        ({"zeta0_range": [0.9, 0.9]}, "zeta0_range", "low below high"),
        ({"zeta0_range": [0.9, 1.0]}, "zeta0_range", "less than 1"),
        ({"psi0_range": [20.0]}, "psi0_range", "at least 2 items"),
        ({"psi0_steps": 0}, "psi0_steps", "greater than or equal to 1"),
        ({"zeta0_steps": 1001}, "zeta0_steps", "less than or equal to 1000"),
        ({"psi0_steps": 1000, "zeta0_steps": 251}, "psi0_steps x zeta0_steps", "at most 250,000 cells"),
        ({"psi0_steps": 500, "zeta0_steps": 500, "jumps": 101}, "psi0_steps x zeta0_steps x jumps", "25,000,000"),
        ({"foot_y": float("nan")}, "foot_y", "finite"),
        ({"world_id": 0}, "world_id", "greater than or equal to 1"),
    ],
)
def test_a_bad_request_is_refused_naming_the_field(changes, field, says):
    with pytest.raises(ValidationError) as refused:
        ReachJobCreate(**({"kind": "reach", "world_id": 1} | changes))
    assert field in str(refused.value) and says in str(refused.value)


def test_the_limits_and_chunks_are_sim_cores_and_the_work_is_within_the_budget():
    assert (reach_job.MAX_CELLS, reach_job.MAX_CELL_JUMPS) == (sim_reach.MAX_CELLS, sim_reach.MAX_CELL_JUMPS)
    assert CHUNK_ROWS == sim_reach.DEFAULT_CHUNK_ROWS
    largest = ReachJobCreate(kind="reach", world_id=1, psi0_steps=500, zeta0_steps=500, jumps=100)
    assert worst_case_jumps(largest) == (25_000_000, "psi0_steps x zeta0_steps x jumps")
    assert reach_job.row_blocks(largest) == 63


def test_the_spec_reads_back_with_its_ranges():
    spec = spec_of(ReachJobCreate(kind="reach", world_id=3, psi0_range=[25, 35], state={"xdot": -1.0, "ydot": 0.5}))
    assert spec.psi0_range == (25.0, 35.0) and spec.zeta0_range == (0.84, 0.96) and spec.world is None
    assert decode(encode(spec)) == spec
