"""The model's prediction of a tracked run's touchdowns (a robot run's or its replay's
``results.prediction``): the model run from the first detected touchdown with the controls each
touchdown was made with, in the chute the run climbed.

Between parallel walls (no ``world_id``) it is the Poincaré map
(:func:`sim_core.model.poincare.iterate_map`). In a stored world the walls are not where the map
assumes, so it is the model's climb in that world (docs/model.md §8,
:func:`sim_core.world.climb.climb_from_touchdown`) from the first touchdown as it was met — its
side, its foot's height, its velocity — read as the map's orbit
(:func:`sim_core.world.climb.section_orbit`). Both have one shape, ``{"states": [[xdot, ydot],
...] [sqrt(g l0)] flipped to the left wall, "rises": [...] [l0] (each jump's next foot's height
minus this foot's), "failure": {"code", "jump"} | None}``; a world's adds ``"world": {"id",
"name"}``, the world that made it (absent: parallel walls).

The kernels load where a prediction is made, not where the service starts.
"""

from __future__ import annotations

from backend.robot.touchdown import Touchdown
from backend.store.models import World
from sim_core.model.controls import ControlSchedule, LegControl
from sim_core.model.params import PhysicalParams
from sim_core.model.walls import Wall


def run_prediction(
    touchdowns: list[Touchdown], controls: list[LegControl], robot: PhysicalParams, world: World | None = None
) -> dict | None:
    """The model's prediction of ``touchdowns`` 1.. from touchdown 0 (None with fewer than two):
    ``controls[k]`` is touchdown ``k``'s leg, ``robot`` the physical parameters, ``world`` the
    stored world the run climbed (None: parallel walls)."""
    if len(touchdowns) < 2:
        return None
    schedule = ControlSchedule.of(*controls[: len(touchdowns)])
    jumps = len(touchdowns) - 1
    if world is None:
        from sim_core.model.poincare import iterate_map

        return iterate_map(robot.to_model(), schedule, touchdowns[0].state, jumps).to_dict()
    return {
        **world_prediction(touchdowns[0], schedule, jumps, robot, world),
        "world": {"id": world.id, "name": world.name},
    }


def world_prediction(
    first: Touchdown, schedule: ControlSchedule, jumps: int, robot: PhysicalParams, world: World
) -> dict:
    """The model's climb of ``jumps`` jumps in the stored ``world`` from the tracked touchdown
    ``first`` (its foot on the side it met at its ``foot_height`` [m], its section state already
    flipped to that side), as the Poincaré map's orbit is given (``Orbit.to_dict``)."""
    from sim_core.world.climb import climb_from_touchdown, section_orbit
    from sim_core.world.files import world_from_document
    from sim_core.world.geometry import LEFT, RIGHT

    chute = world_from_document(world.document, robot.leg_length)  # a world in metres needs l0
    side = LEFT if first.wall == Wall.LEFT else RIGHT
    foot_y = first.foot_height / robot.leg_length
    climb = climb_from_touchdown(robot.to_model(), chute, schedule, first.state, jumps, side=side, foot_y=foot_y)
    return section_orbit(climb, schedule).to_dict()
