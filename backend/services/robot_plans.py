"""A live run's world and plan, read from the store before anything moves: the world the robot
climbs (a run's ``world_id``, or the plan job's) as the sides the touchdown detector meets, and a
``plan`` job's plan as the run's law (:class:`backend.robot.plan_law.PlanLaw`), its start legs
the plan's first two. Every refusal is a 422 naming the field (a 404 for a world or job that is not
there); the law's kernels are compiled here, before the run starts."""

from __future__ import annotations

from dataclasses import dataclass

from sqlalchemy.orm import Session

from backend.repositories import jobs as stored_jobs
from backend.repositories import worlds as stored_worlds
from backend.robot.limits import ServoLimits
from backend.robot.plan_law import PlanLaw
from backend.robot.touchdown import SideAt
from backend.schemas.jobs import JobState
from sim_core.model.controls import LegControl
from sim_core.model.errors import ParameterError
from sim_core.model.params import PhysicalParams
from sim_core.model.walls import Wall


@dataclass(frozen=True)
class RunWorld:
    """A live run's world (None: parallel walls), its sides as the detector meets them, its plan's law."""

    world_id: int | None = None
    side_at: SideAt | None = None
    law: PlanLaw | None = None

    @property
    def legs(self) -> list[LegControl] | None:
        """The plan's start legs [left, right] (None without a plan)."""
        return None if self.law is None else self.law.start_legs()


def run_world(session: Session, body, robot: PhysicalParams, limits: ServoLimits) -> RunWorld:
    """The world and plan ``body`` (a :class:`backend.schemas.RobotRunCreate`) names, on ``robot``."""
    from sim_core.world.files import world_from_document

    if body.plan_job_id is not None:
        job = stored_jobs.get(session, body.plan_job_id)
        steps, document = _plan_of(job, body.world_id)
        world = world_from_document(document)
        law = PlanLaw(_live_plan(robot, world, steps), job.spec["goal_height_m"], robot.leg_length, limits=limits)
        law.warm()
        return RunWorld(job.world_id, sides_at(world, robot), law)
    if body.world_id is not None:
        return RunWorld(body.world_id, world_sides(session, body.world_id, robot))
    return RunWorld()


def world_sides(session: Session, world_id: int, robot: PhysicalParams) -> SideAt:
    """The stored world ``world_id``'s sides for the touchdown detector (a 404 if there is none)."""
    from sim_core.world.files import world_from_document

    return sides_at(world_from_document(stored_worlds.get(session, world_id).document, robot.leg_length), robot)


def sides_at(world, robot: PhysicalParams) -> SideAt:
    """``world``'s sides for the touchdown detector: a side's x [m] at a height [m] (SI, ``robot``'s leg length)."""
    from sim_core.world.geometry import LEFT, RIGHT, pack, side_x

    sides, metres = pack(world, robot.to_model().mu), robot.leg_length

    def side_at(wall: Wall, height_m: float) -> float:
        return float(side_x(sides, LEFT if wall == Wall.LEFT else RIGHT, height_m / metres)) * metres

    return side_at


def _plan_of(job, world_id: int | None) -> tuple[list[dict], dict]:
    """The plan job's steps and its world's §8 JSON (l0); a 422 at ``plan_job_id`` where it has none."""
    if job.kind != "plan":
        raise ParameterError("plan_job_id", f"job {job.id} is a {job.kind} job, not a plan")
    if job.state != JobState.DONE or not (job.result or {}).get("reaches_goal"):
        said = "has no plan to its goal" if job.state == JobState.DONE else f"is {job.state}"
        raise ParameterError("plan_job_id", f"plan job {job.id} {said}: only a finished plan that reaches its goal")
    if world_id is not None and world_id != job.world_id:
        raise ParameterError("world_id", f"plan job {job.id} is in world {job.world_id}, not {world_id}")
    steps = job.result["plan"]
    if any("velocity" not in step for step in steps):
        raise ParameterError("plan_job_id", f"plan job {job.id} was made before plans kept their velocities: "
                             "plan again")  # fmt: skip
    return steps, job.spec["world"]


def _live_plan(robot: PhysicalParams, world, steps: list[dict]):
    from sim_core.planning.live import LivePlan

    return LivePlan.of(robot.to_model(), world, steps)
