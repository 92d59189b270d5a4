"""What the kinds that work in a stored world share: the request's fields (the world's id, the
goal in metres, the body's velocity at touchdown 0), the world as the spec keeps it (its §8 JSON
in ``l0``, copied when the job was accepted: the job reads no store) and the goal checked in it.

Which world a job works in is the job's ``world_id`` (:class:`backend.store.models.Job`): the
service copies the world into the spec (:func:`backend.services.jobs.create_job`) and refuses to
delete a world a job uses.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Annotated

from pydantic import Field

from backend.schemas.common import MAX_ID

if TYPE_CHECKING:
    from sim_core.model.params import PhysicalParams
    from sim_core.world.world import World

# A plan search's flights: the planner's grid of legs (13 x 9) x its noisy draws (8) x its beam (24)
# x its most jumps (80). The wider second search (where the first finds no way) and a climb's
# replans (rare: 0.0 a trial in the foothold study's default worlds) are not counted.
PLAN_SEARCH_JUMPS = 117 * 8 * 24 * 80
WorldRef = Annotated[int, Field(ge=1, le=MAX_ID, description="a stored world's id (GET /api/v1/worlds)")]
GoalHeightM = Annotated[
    float, Field(gt=0.0, le=100.0, description="the height a foot must reach [m], within the world")
]


def world_of(spec) -> World:
    """The spec's stored world (its §8 JSON in ``l0``) as sim_core's World."""
    from sim_core.world.files import world_from_document

    if spec.world is None:  # accepted without its world: the service copies it in (a bug if not)
        raise ValueError(f"job spec of kind {spec.kind!r} holds no world (world_id {spec.world_id})")
    return world_from_document(spec.world)


def label_of(spec) -> str:
    """The stored world as a person knows it: its name, or ``world N``."""
    return (spec.world or {}).get("name") or f"world {spec.world_id}"


def goal_in_l0(spec, robot: PhysicalParams) -> float:
    """The spec's goal height [m] in leg lengths."""
    return spec.goal_height_m / robot.leg_length


def check_goal_in(world: World, spec, robot: PhysicalParams, *, label: str, footholds: bool = True) -> None:
    """A ParameterError naming ``goal_height_m`` where the goal cannot be reached in ``world`` (said in metres)."""
    from sim_core.model.errors import ParameterError
    from sim_core.planning.goals import check_goal

    try:
        check_goal(world, goal_in_l0(spec, robot), 0.0, name=label, metres=robot.leg_length, footholds=footholds)
    except ParameterError as error:
        field = "goal_height_m" if error.field == "goal_height" else "world_id"
        raise ParameterError(field, error.message) from None
