"""A live run in a world, following a plan (backend/services/robot_plans.py, backend/robot/plan_law.py):
the virtual robot climbs a random-foothold world (its hidden physics), the service plans in the
same stored world, and the run follows the plan with the placement law: it ends cleanly — at the
plan's goal, or at a foot off its foothold, said as such — disarmed, stored with its world, each
command journaled with its target foothold."""

import pytest

from backend.jobs.plan import PlanJobCreate
from backend.repositories import runs as run_store
from backend.robot.virtual import VirtualRobot
from backend.schemas import RobotConnect, RobotRunCreate
from backend.schemas.worlds import WorldCreate
from backend.services import job_runner, jobs, worlds
from sim_core import get_preset
from sim_core.model.errors import ParameterError
from sim_core.model.noise import NO_NOISE
from sim_core.world.random_world import random_world
from tests.helpers import free_port

RUN_WAIT_S = 60.0  # [s] an upper bound for a short climb in real time, not a timing assertion
ENDINGS = ("goal reached", "missed foothold", "off plan")


@pytest.fixture
def climbing(service):
    """The robot service connected to a noiseless virtual robot climbing random world 5, in real time."""
    import socket

    model = get_preset("paper").to_model()
    port = free_port(socket.SOCK_DGRAM)
    robot = VirtualRobot(tracker_to=("127.0.0.1", port), noise=NO_NOISE, speed=1.0, seed=2,
                         world=random_world(5, width=model.d_hat)).start()  # fmt: skip
    try:
        status = service.connect(RobotConnect(url=robot.url, tracker_port=port))
        assert status["state"] == "disarmed", status
        yield service
    finally:
        service.close()
        robot.stop()


def planned(sessions, session, compute, world_id: int, goal_m: float) -> int:
    """A plan job from the velocity a robot launched on its first leg has (that leg's gait's)."""
    body = {"kind": "plan", "world_id": world_id, "goal_height_m": goal_m, "launch_gait": True}
    job = jobs.create_job(session, PlanJobCreate(**body))
    job_runner.JobRunner(sessions, compute.jobs).run(job.id)
    done = jobs.get_job(session, job.id)
    assert done.state == "done" and jobs.job_results(session, job.id).result["reaches_goal"], done.error
    return job.id


@pytest.mark.realtime  # the law answers each touchdown within the next stance, as on the robot
def test_a_live_run_follows_a_plan_in_its_world_and_ends_cleanly(climbing, sessions, session, compute):
    world = worlds.create(session, WorldCreate(name="holds 5", random={"seed": 5}))
    plan_job = planned(sessions, session, compute, world.id, 1.0)
    plan = jobs.job_results(session, plan_job).result["plan"]
    climbing.start_run(RobotRunCreate(plan_job_id=plan_job, jumps=40, max_seconds=30.0))
    snapshot = climbing.wait_run(RUN_WAIT_S)
    assert not snapshot.active, "the live run did not end"
    status = climbing.status()
    assert status["state"] == "disarmed", "every ending disarms"
    reason = snapshot.end_reason
    assert reason.split(":")[0] in ENDINGS, reason
    stored = run_store.get_run(session, status["run"]["stored_run_id"])
    assert stored.world_id == world.id and stored.results["plan_job_id"] == plan_job
    assert stored.status == ("done" if reason.startswith("goal reached") else "failed")
    assert stored.controls == [[plan[0]["psi0_deg"], plan[0]["zeta0"]], [plan[1]["psi0_deg"], plan[1]["zeta0"]]]
    aimed = [command for command in stored.results["commands"] if command["why"] != "start"]
    for command in aimed:
        target = command["target"]
        step = plan[target["touchdown"]]
        assert (target["side"], target["segment"]) == (step["side"], step["segment"]), command
    print(f"{reason}; {len(stored.results['touchdowns'])} touchdowns, {len(aimed)} commands aimed")
    assert reason.startswith("goal reached") and len(aimed) >= 1, "a noiseless robot on its plan gets there"


def test_a_plan_run_is_refused_before_anything_moves(connected, sessions, session, compute):
    walls = worlds.create(session, WorldCreate(name="walls", named="parallel"))
    with pytest.raises(ParameterError, match=r"plan_job_id: plan job \d+ is queued: only a finished plan"):
        job = jobs.create_job(session, PlanJobCreate(kind="plan", world_id=walls.id, goal_height_m=0.5))
        connected.start_run(RobotRunCreate(plan_job_id=job.id))  # queued: not a finished plan
    assert connected.status()["state"] == "disarmed"


def test_a_live_run_tells_the_live_view_the_world_it_climbs(connected, session):
    """The live 3D view draws a run's world from its snapshot (frontend/viewer/modes/live_world.py)."""
    walls = worlds.create(session, WorldCreate(name="walls", named="parallel"))
    legs = [{"psi0_deg": 30.0, "zeta0": 0.87}, {"psi0_deg": 30.0, "zeta0": 0.9}]
    snapshot = connected.start_run(RobotRunCreate(controls=legs, world_id=walls.id, jumps=2))
    try:
        assert (snapshot.world_id, snapshot.plan_job_id) == (walls.id, None)
        assert connected.status()["run"]["world_id"] == walls.id
    finally:
        connected.stop_run()
    assert not connected.run_snapshot().active and connected.run_snapshot().world_id == walls.id
