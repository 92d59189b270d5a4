"""Live mode in a stored world (frontend/viewer/modes/live_world.py): a live run that climbs a world
is drawn in it — its sides in place of the parallel walls, read once for the run, the ruler on its
left side, each touchdown marked where the foot met its side, no parallel-walls ghost — and the next
run without a world between the parallel walls again; a run that follows a plan has its footholds
marked hit or missed as its touchdowns pass, the next one aimed at while it runs.

Drawn as tests/frontend/viewer/modes/test_live.py draws live mode: on a private viser server's
scene, recorded frame by frame, what the browser gets decoded as it decodes it.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from backend.robot.touchdown import Touchdown
from backend.schemas.worlds import WorldCreate
from backend.services import worlds
from backend.store.models import Job
from frontend.viewer.modes.live_world import GHOST_WORDS
from frontend.viewer.scene import AIM_COLOR, TARGET_HIT, TARGET_MISSED
from frontend.viewer.world_slabs import world_slabs
from sim_core.model.controls import LegControl
from sim_core.model.walls import Wall
from sim_core.world.files import world_to_document
from sim_core.world.world import Side, World
from tests.frontend.viewer.modes.test_live import ROBOT, Live

L0 = ROBOT.leg_length  # [m]
HALF = 0.5 * ROBOT.wall_distance  # [m] the centre line to a parallel wall's face
# Wider than the parallel walls at the floor, its left side leaning in above 1.5 l0.
FUNNEL = World(
    Side(np.array([[-1.4, 0.0], [-1.4, 1.5], [-1.0, 3.0]]), np.array([0.0, 1.0])),
    Side(np.array([[1.21, 0.0], [1.21, 3.0]]), np.array([math.inf])),
    "funnel",
)
LEG = LegControl.from_degrees(30, 0.9)


@dataclasses.dataclass
class Counted:
    """A session factory that counts the sessions it opens."""

    sessions: object
    opened: int = 0

    def __call__(self):
        self.opened += 1
        return self.sessions()


def stored(sessions, world: World) -> int:
    with sessions() as session:
        return worlds.create(session, WorldCreate(name=world.name, world=world_to_document(world))).id


def touchdown(index: int, wall: Wall, foot_l0: float) -> Touchdown:
    """Detected touchdown ``index`` on ``wall``, its foot ``foot_l0`` [l0] up."""
    foot = foot_l0 * L0
    return Touchdown(index, 0.5 * (index + 1), wall, (-0.8, -0.15), foot + 0.1, foot, 20)


def markers(scene: dict) -> list[tuple[float, float, float]]:
    return sorted(node["position"] for name, node in scene.items() if name.startswith("/chute/touchdowns/"))


def test_a_live_run_in_a_stored_world_is_drawn_in_it_and_the_next_run_without_one_between_the_walls(server, sessions):
    world_id = stored(sessions, FUNNEL)
    counted = Counted(sessions)
    live = Live(server, counted)
    scene, calibrations_read = live.mode.scene, counted.opened  # the ghost's models, listed once
    live.run(1.0, start_height=0.1, world_id=world_id)
    assert counted.opened == calibrations_read + 1, "the world is read once for the run, not at each of its frames"
    assert scene.world is not None and scene.world.name == "funnel"
    assert not any(wall.visible for wall in scene.walls), "its sides in place of the parallel walls"
    assert scene.chute_words == "world 'funnel', sides 0.49 m to 0.58 m apart"
    # The ghost would jump between parallel walls: it is not drawn in a world.
    climbed = (touchdown(0, Wall.LEFT, 1.0), touchdown(1, Wall.RIGHT, 2.0), touchdown(2, Wall.LEFT, 2.5))
    live.robot.run = dataclasses.replace(live.robot.run, touchdowns=climbed, touchdown_controls=(LEG,) * 3)
    live.frame()
    in_world = live.frames - 1
    assert live.mode._ghost(climbed, 2) is not None and not scene.ghost.visible
    assert GHOST_WORDS in live.mode.run_world.words() and f"world {world_id} 'funnel'" in live.mode.run_world.words()

    live.run(1.0, start_height=0.1)  # no world: the parallel walls
    live.robot.run = dataclasses.replace(live.robot.run, touchdowns=climbed[:1])
    live.frame()
    assert counted.opened == calibrations_read + 1, "a run in no world reads nothing"
    assert scene.world is None and all(wall.visible for wall in scene.walls)
    assert scene.chute_words == f"walls {ROBOT.wall_distance:.2f} m apart"

    frames = live.recorded()
    drawn, _ = frames[in_world]
    slabs = {name.removeprefix("/chute/world/") for name in drawn if name.startswith("/chute/world/")}
    assert slabs == {slab.name for slab in world_slabs(FUNNEL, L0, ROBOT.to_model().mu)}, "what the browser got"
    feet = [(-1.4 * L0, 0.0, 1.0 * L0), (1.21 * L0, 0.0, 2.0 * L0), ((-1.4 + 0.4 / 1.5) * L0, 0.0, 2.5 * L0)]
    np.testing.assert_allclose(markers(drawn), sorted(feet), atol=1e-6, err_msg="each foot on its side")
    np.testing.assert_allclose(drawn["/chute/ruler"]["position"], (-1.4 * L0 + HALF, 0.0, 0.0), atol=1e-6)
    after, _ = frames[-1]
    assert not any(name.startswith("/chute/world/") for name in after)
    assert all(name in after for name in ("/chute/wall_left", "/chute/wall_right"))
    np.testing.assert_allclose(markers(after), [(-HALF, 0.0, 1.0 * L0)], atol=1e-6, err_msg="on the parallel wall")
    np.testing.assert_allclose(after["/chute/ruler"]["position"], (0.0, 0.0, 0.0), atol=1e-6)


def test_a_followed_plans_footholds_are_marked_hit_or_missed_and_the_next_aimed_at(server, sessions):
    world_id = stored(sessions, FUNNEL)
    # One foothold per touchdown of the plan's climb (row 0: the start, before the first one detected).
    footholds = [
        ("left", 0, (-1.4, 0.5)),
        ("right", 0, (1.21, 1.0)),
        ("left", 1, (-1.3, 1.9)),
        ("right", 0, (1.21, 2.6)),
    ]
    plan = [{"side": side, "segment": segment, "target": list(target)} for side, segment, target in footholds]
    with sessions() as session:
        job = Job(kind="plan", spec={}, state="done", total=1, code_version="test", result={"plan": plan},
                  world_id=world_id)  # fmt: skip
        session.add(job)
        session.commit()
        job_id = job.id
    live = Live(server, Counted(sessions))
    scene = live.mode.scene
    live.run(0.5, start_height=0.1, world_id=world_id, plan_job_id=job_id)
    assert scene.aim.visible and scene.aim.color == AIM_COLOR
    np.testing.assert_allclose(scene.aim.position, (1.21 * L0, -0.04, 1.0 * L0), err_msg="the first detected's")
    # The right foot on its planned foothold; the left one still on segment 0, planned on 1.
    climbed = (touchdown(0, Wall.RIGHT, 1.0), touchdown(1, Wall.LEFT, 1.2))
    live.robot.run = dataclasses.replace(live.robot.run, touchdowns=climbed)
    live.frame()
    hit, missed = scene.targets.nodes[:2]
    assert (hit.visible, hit.color, missed.visible, missed.color) == (True, TARGET_HIT, True, TARGET_MISSED)
    np.testing.assert_allclose(missed.position, (-1.3 * L0, -0.04, 1.9 * L0))
    np.testing.assert_allclose(scene.aim.position, (1.21 * L0, -0.04, 2.6 * L0), err_msg="the next one's")
    live.robot.run = dataclasses.replace(live.robot.run, active=False)
    live.frame()
    assert not scene.aim.visible, "an ended run aims at nothing"
    assert f"following plan job {job_id}" in live.mode.run_world.words()
