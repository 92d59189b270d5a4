"""A plan as a job (backend/jobs/plan.py): in a stored world, its result the command's, its
attempts counted the same twice, a plan that cannot reach its goal a result that says how high it
got, and its bad requests refused naming the field."""

import pytest
from pydantic import ValidationError

from backend.jobs import worst_case_jumps
from backend.jobs.plan import PlanJobCreate
from backend.schemas.job_budget import WORK_BUDGET_JUMPS
from backend.schemas.worlds import WorldCreate
from backend.services import job_runner, jobs, worlds
from sim_core import get_preset
from sim_core.model.errors import ParameterError
from tests.backend.services.jobs_helpers import job_now
from tests.cli.helpers import json_of


def planned(sessions, session, compute, **fields) -> dict:
    job = jobs.create_job(session, PlanJobCreate(**({"kind": "plan", "goal_height_m": 0.5} | fields)))
    job_runner.JobRunner(sessions, compute.jobs).run(job.id)
    done = job_now(sessions, job.id)
    assert done.state == "done", done.error
    return done


def test_a_plan_job_is_the_commands_plan_of_the_same_world(sessions, session, compute):
    stairs = worlds.create(session, WorldCreate(name="stairs", named="staircase"))
    done = planned(sessions, session, compute, world_id=stairs.id, seed=2)
    result = dict(jobs.job_results(session, done.id).result)
    command = json_of("plan", "--world", "staircase", "--goal-height", "0.5", "--seed", "2")
    assert result.pop("world") == "stairs" and len(result.pop("state")) == 2 and done.world_id == stairs.id
    metres = result.pop("leg_length_m")
    assert result.pop("goal_l0") == pytest.approx(0.5 / metres, rel=1e-15) and metres == get_preset("paper").leg_length
    for document in (result, command):
        document.pop("seconds")
    assert result == command and command["reaches_goal"] and len(command["plan"]) >= 2


def test_a_plans_attempts_are_counted_the_same_twice(sessions, session, compute):
    held = worlds.create(session, WorldCreate(name="holds 4", random={"seed": 4}))
    checks = [jobs.job_results(session, planned(sessions, session, compute, world_id=held.id, attempts=40,
                                                replans=0).id).result["monte_carlo"] for _ in range(2)]  # fmt: skip
    for check in checks:
        check.pop("seconds")
    assert checks[0] == checks[1] and checks[0]["trials"] == 40 and 0 <= checks[0]["failures"] <= 40


def test_a_goal_no_plan_reaches_is_said_not_failed(sessions, session, compute):
    """The planner says how high it got (the command refuses; a job keeps what it found)."""
    walls = worlds.create(session, WorldCreate(name="walls", named="parallel"))
    done = planned(sessions, session, compute, world_id=walls.id, goal_height_m=1.9)
    result = jobs.job_results(session, done.id).result
    assert result["reaches_goal"] in (True, False) and result["highest_m"] > 0
    if not result["reaches_goal"]:
        assert result["highest_m"] < 1.9 and "monte_carlo" not in result


def test_a_plans_importance_sampling_is_sim_cores(sessions, session, compute):
    from sim_core.model.noise import NoiseModel
    from sim_core.planning.launch import start_velocity
    from sim_core.planning.plan_importance import plan_importance
    from sim_core.planning.plan_splitting import PlanSplitting
    from sim_core.planning.planner import plan_climb
    from sim_core.world.files import world_from_document

    held = worlds.create(session, WorldCreate(name="holds 4", random={"seed": 4}))
    sampling = {"trials": 300, "scale": 2.0, "draws": ["psi0"], "first_leg": True}
    done = planned(sessions, session, compute, world_id=held.id, seed=3, replans=0, importance_sampling=sampling)
    result = jobs.job_results(session, done.id).result
    assert "monte_carlo" not in result and (done.completed, done.total) == (2, 2), "the search, then the climbs"
    robot = get_preset("paper")
    model, world, goal = robot.to_model(), world_from_document(held.world), 0.5 / robot.leg_length
    plan = plan_climb(model, world, goal, start_velocity(model), seed=3)
    options = PlanSplitting(seed=3, cap=200, max_replans=0)
    expected = plan_importance(model, world, plan, goal, NoiseModel(), options, 300, 3, 2.0, scaled=("psi0",),
                               first_leg_only=True).to_dict()  # fmt: skip
    got = result["importance_sampling"]
    for document in (got, expected):
        document.pop("seconds")
    assert got == expected and got["trials"] == 300 and got["scaled"] == ["psi0"] and got["first_leg_only"]


def test_the_plan_jobs_importance_limits_are_sim_cores():
    from backend.jobs.plan import DRAW_KINDS, SCALE_LIMITS
    from sim_core.model.noise_rules import TALLY_KINDS
    from sim_core.planning import plan_importance

    assert (DRAW_KINDS, SCALE_LIMITS) == (TALLY_KINDS, plan_importance.SCALE_LIMITS)


@pytest.mark.parametrize(
    ("changes", "field"),
    [({}, "world_id"), ({"world_id": 1, "goal_height_m": 0}, "goal_height_m"), ({"world_id": 1, "attempts": -1},
     "attempts"), ({"world_id": 1, "attempts": 100_000, "cap": 10_000}, "over the limit"),
     ({"world_id": 1, "importance_sampling": {"trials": 100, "scale": 6}}, "importance_sampling.scale"),
     ({"world_id": 1, "importance_sampling": {"trials": 100, "draws": ["leg"]}}, "importance_sampling.draws"),
     ({"world_id": 1, "importance_sampling": {"trials": 1}}, "importance_sampling.trials"),
     ({"world_id": 1, "importance_sampling": {"trials": 100_000}, "cap": 10_000}, "importance_sampling.trials) x cap")],
)  # fmt: skip
def test_a_bad_plan_is_refused_naming_the_field(changes, field):
    with pytest.raises(ValidationError) as refused:
        PlanJobCreate(**({"kind": "plan", "goal_height_m": 0.5} | changes))
    assert field in str(refused.value)


def test_a_goal_above_the_world_is_refused_in_metres(session):
    stairs = worlds.create(session, WorldCreate(name="stairs", named="staircase"))
    with pytest.raises(ParameterError, match=r"goal_height_m: must be at most stairs's top \(\d"):
        jobs.create_job(session, PlanJobCreate(kind="plan", world_id=stairs.id, goal_height_m=99.0))
    jumps, _ = worst_case_jumps(PlanJobCreate(kind="plan", world_id=1, goal_height_m=0.5, attempts=1000))
    assert 0 < jumps <= WORK_BUDGET_JUMPS
