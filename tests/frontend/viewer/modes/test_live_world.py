"""Live mode in a stored world (frontend/viewer/modes/live_world.py): a live run that climbs a world
is drawn in it — its sides in place of the parallel walls, read once for the run, the ruler on its
left side, each touchdown marked where the foot met its side — and the next run without a world
between the parallel walls again; a run that follows a plan has its footholds marked hit or missed
as its touchdowns pass, the next one aimed at while it runs. The model's ghost jumps in the world
(frontend/viewer/world_ghost.py): from each touchdown on either side to the next touchdown the
world's climb predicts (sim_core.world.climb.climb_from_touchdown), never through the sides, with
the paper's model or a calibration, streamed a piece at a time; a jump the model fails there is
drawn up to the failure and the readout says so.

Drawn as tests/frontend/viewer/modes/test_live.py draws live mode: on a private viser server's
scene, recorded frame by frame, what the browser gets decoded as it decodes it.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from backend.robot.touchdown import Touchdown
from backend.robot.tracker import Pose
from backend.schemas.worlds import WorldCreate
from backend.services import worlds
from backend.store.models import Job, ModelPreset
from frontend.viewer.scene import AIM_COLOR, TARGET_HIT, TARGET_MISSED
from frontend.viewer.simulated_climb import model_jump
from frontend.viewer.world_slabs import world_slabs
from sim_core.model.controls import ControlSchedule, LegControl
from sim_core.model.failures import Failure
from sim_core.model.walls import Wall
from sim_core.planning.launch import start_velocity
from sim_core.world.climb import climb_from_touchdown, section_orbit
from sim_core.world.files import world_to_document
from sim_core.world.geometry import LEFT, RIGHT, pack, side_x
from sim_core.world.world import Side, World
from tests.frontend.viewer.modes.test_live import (
    FRAME_RATE,
    FRAME_TRAIL_BYTES,
    ROBOT,
    TRACKER_RATE,
    Live,
    _array_bytes,
    _copy,
)
from tests.frontend.viewer.test_share import SceneTree, decode_recording
from tests.tracked_climbs import Truth

L0 = ROBOT.leg_length  # [m]
HALF = 0.5 * ROBOT.wall_distance  # [m] the centre line to a parallel wall's face
# Wider than the parallel walls at the floor, its left side leaning in above 1.5 l0.
FUNNEL = World(
    Side(np.array([[-1.4, 0.0], [-1.4, 1.5], [-1.0, 3.0]]), np.array([0.0, 1.0])),
    Side(np.array([[1.21, 0.0], [1.21, 3.0]]), np.array([math.inf])),
    "funnel",
)
LEG = LegControl.from_degrees(30, 0.9)
# Wider than the parallel walls and shifted left of them, its left side leaning in: the parallel
# walls' ghost would stand its body on the right wall's side of x = 0.43 l0, through this right side.
SHIFTED = World(
    Side(np.array([[-2.2, 0.0], [-2.2, 1.0], [-2.0, 2.0], [-2.0, 4.0]]), np.full(3, math.inf)),
    Side(np.array([[0.2, 0.0], [0.2, 4.0]]), np.array([math.inf])),
    "shifted",
)


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


def touchdown(
    index: int, wall: Wall, foot_l0: float, *, world: World = FUNNEL, state=(-0.8, -0.15), time: float | None = None
) -> Touchdown:
    """Detected touchdown ``index`` on ``wall``, its foot ``foot_l0`` [l0] up on ``world``'s side,
    the body where ``LEG`` puts it, arriving with section ``state`` (flipped), at ``time`` [s]."""
    side = world.left if wall == Wall.LEFT else world.right
    body_x = (side.x_at(foot_l0) - wall * LEG.zeta0 * math.cos(LEG.psi0)) * L0
    body = (foot_l0 + LEG.zeta0 * math.sin(LEG.psi0)) * L0
    time = 0.5 * (index + 1) if time is None else time
    return Touchdown(index, time, wall, tuple(state), body, foot_l0 * L0, 20, body_x=body_x)


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
    # The ghost jumps in the world: the last touchdown's foot is on the left side's overhang, where
    # the model's leg leaves the friction cone at once; the ghost stays at the touchdown, and says so.
    climbed = (touchdown(0, Wall.LEFT, 1.0), touchdown(1, Wall.RIGHT, 2.0), touchdown(2, Wall.LEFT, 2.5))
    live.robot.run = dataclasses.replace(live.robot.run, touchdowns=climbed, touchdown_controls=(LEG,) * 3)
    live.frame()
    in_world = live.frames - 1
    assert live.mode._ghost(climbed, 2).failure is Failure.SLIP and scene.ghost.visible
    np.testing.assert_allclose(scene.ghost.position, (climbed[2].body_x, 0.0, climbed[2].body_height), atol=1e-9)
    assert "from touchdown 2 fails in the world: slip" in live.mode.ghost_words()
    assert f"world {world_id} 'funnel'" in live.mode.run_world.words()

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


def advance(live: Live, until: float) -> None:
    """Tracker frames at the tracker's rate from the latest one's time to ``until`` [s] (the body
    standing mid-chute), the view drawing at its own rate meanwhile."""
    start = live.robot.tracker.latest().time
    times = np.arange(start + 1 / TRACKER_RATE, until, 1 / TRACKER_RATE)
    fed = 0
    for k in range(1, int((until - start) * FRAME_RATE) + 2):
        while fed < times.size and times[fed] <= start + k / FRAME_RATE:
            live.robot.tracker.add(Pose(float(times[fed]), -0.2, 0.3))
            fed += 1
        live.frame()


def predicted(model, world: World, detected: Touchdown, leg: LegControl, next_leg: LegControl):
    """The world's climb of one jump from ``detected`` (model ``model``, world in its l0 = L0):
    the climb and its schedule."""
    schedule = ControlSchedule.of(leg, next_leg)
    side = LEFT if detected.wall == Wall.LEFT else RIGHT
    climb = climb_from_touchdown(model, world, schedule, detected.state, 1, side=side,
                                 foot_y=detected.foot_height / L0)  # fmt: skip
    return climb, schedule


def ghost_frames(live: Live) -> list[tuple[dict, int]]:
    """After each frame: the browser's scene, and the bytes of arrays the frame sent for the ghost's
    trail (as :meth:`Live.recorded` counts the robot's)."""
    messages = decode_recording(live.serializer.serialize())["messages"]
    tree, out, i = SceneTree(), [], 0
    for frame in range(live.frames):
        sent = 0
        while i < len(messages) and messages[i][0] <= (frame + 0.5) / FRAME_RATE:
            message = messages[i][1]
            tree.apply(message)
            if message.get("name", "").startswith("/chute/ghost/live"):
                sent += _array_bytes(message)
            i += 1
        out.append((_copy(tree), sent))
    return out


def ghost_trail_points(scene: dict) -> np.ndarray:
    """The points of the ghost's trail the browser draws, (n, 2): ``x``, ``y`` [m]."""
    segments = [
        node["props"]["points"].reshape(-1, 2, 3)
        for name, node in scene.items()
        if name.startswith("/chute/ghost/live/") and node["kind"] == "LineSegmentsMessage"
    ]
    drawn = np.concatenate(segments).astype(float)
    drawn = drawn[np.any(drawn[:, 0] != drawn[:, 1], axis=1)]  # a ring's unused nodes draw nothing
    return drawn.reshape(-1, 3)[:, [0, 2]]


def assert_between_the_sides(world: World, points: np.ndarray, what: str) -> None:
    sides = pack(world, ROBOT.to_model().mu)
    for x, y in points:
        left, right = side_x(sides, LEFT, y / L0) * L0, side_x(sides, RIGHT, y / L0) * L0
        assert left < x < right, (
            f"{what}: the body at ({x:.4f}, {y:.4f}) m is outside the sides ({left:.4f}, {right:.4f})"
        )


def test_the_ghost_jumps_in_the_world_from_each_touchdown_to_the_next_the_world_predicts(server, sessions):
    world_id = stored(sessions, SHIFTED)
    live = Live(server, Counted(sessions))
    mode, model = live.mode, ROBOT.to_model()
    live.run(1.0, start_height=0.1, world_id=world_id)
    # The parallel walls' jump stands on the wall at x = +d/2: its body passes this world's right side.
    first = touchdown(0, Wall.RIGHT, 1.0, world=SHIFTED, state=start_velocity(model), time=1.0)
    between_walls = model_jump(ROBOT, first.state, LEG, LEG, wall=first.wall, start_time=1.0,
                               start_height=first.body_height).clip  # fmt: skip
    assert np.any(between_walls.x > SHIFTED.right.points[0, 0] * L0)

    climbed: tuple[Touchdown, ...] = ()
    ends = []  # each jump's: the frame drawn after it ended, its touchdown and the predicted next one
    for k, detected in enumerate((first, None)):
        if detected is None:  # the robot as the model: its next touchdown where the world's climb put it
            climb, schedule = predicted(model, SHIFTED, climbed[-1], LEG, LEG)
            foot = climb.states[1, 1] - LEG.zeta0 * math.sin(LEG.psi0)
            detected = touchdown(k, Wall.LEFT, foot, world=SHIFTED, state=section_orbit(climb, schedule).states[1],
                                 time=climbed[-1].time + 0.8)  # fmt: skip
        climbed = (*climbed, detected)
        controls = (LEG,) * len(climbed)
        live.robot.run = dataclasses.replace(live.robot.run, touchdowns=climbed, touchdown_controls=controls)
        advance(live, detected.time + 0.7)  # past the jump's end
        ghost = mode._ghost(climbed, k)
        clip, (climb, _schedule) = ghost.clip, predicted(model, SHIFTED, detected, LEG, LEG)
        assert ghost.failure is None and climb.failure is None and mode.ghost_words() == ""
        assert clip.end < detected.time + 0.7 and mode.scene.ghost.visible
        np.testing.assert_allclose((clip.x[0], clip.y[0]), (detected.body_x, detected.body_height), atol=1e-9,
                                   err_msg="the ghost starts at the touchdown's body")  # fmt: skip
        np.testing.assert_allclose((clip.x[-1], clip.y[-1]), climb.states[1, :2] * L0, rtol=0, atol=1e-6 * L0,
                                   err_msg="it ends at the next touchdown the world's climb predicts")  # fmt: skip
        assert int(climb.sides[1]) != (LEFT if detected.wall == Wall.LEFT else RIGHT), "on the other side"
        assert_between_the_sides(SHIFTED, np.column_stack([clip.x, clip.y]), f"jump {k}'s samples")
        ends.append((live.frames - 1, detected, climb.states[1, :2] * L0))

    # What the browser got: the ghost on the next touchdown, its trail from the touchdown, inside the sides.
    frames = ghost_frames(live)
    for k, (frame, detected, landing) in enumerate(ends):
        scene, _ = frames[frame]
        body = scene["/chute/ghost/body"]["position"]
        np.testing.assert_allclose((body[0], body[2]), landing, rtol=0, atol=1e-6 * L0)
        trail = ghost_trail_points(scene)
        assert np.min(np.hypot(*(trail - (detected.body_x, detected.body_height)).T)) < 1e-6, "from the touchdown"
        assert_between_the_sides(SHIFTED, trail, f"jump {k}'s trail as drawn")
    sent = max(ghost_bytes for _scene, ghost_bytes in frames)
    assert sent <= FRAME_TRAIL_BYTES, f"a frame sent {sent} B of the ghost's trail: the trail is sent whole"


def test_the_ghost_in_a_world_predicts_with_the_calibration_chosen(server, sessions):
    truth = Truth.of(alpha=72.0, c_zeta=1.25, c_psi=0.8, psi0_offset_deg=(0.6, -0.8), zeta0_offset=(0.004, -0.005))
    with sessions() as session:
        session.add(ModelPreset(name="truth", base="paper", physical=dataclasses.asdict(truth.robot),
                                offsets=truth.offsets.to_dict(), fit={}, runs=[], code_version="test"))  # fmt: skip
        session.commit()
    world_id = stored(sessions, SHIFTED)
    live = Live(server, Counted(sessions))
    live.mode.use_ghost_model("truth")
    live.run(1.0, start_height=0.1, world_id=world_id)
    detected = touchdown(0, Wall.RIGHT, 1.0, world=SHIFTED, state=start_velocity(ROBOT.to_model()), time=1.0)
    live.robot.run = dataclasses.replace(live.robot.run, touchdowns=(detected,), touchdown_controls=(LEG,))
    advance(live, 1.7)
    # Each leg as the calibration's offsets realise it: the right one standing, the left one flying.
    leg, next_leg = truth.offsets.applied(LEG, right_leg=True), truth.offsets.applied(LEG, right_leg=False)
    climb, _schedule = predicted(truth.robot.to_model(), SHIFTED, detected, leg, next_leg)
    paper, _schedule = predicted(ROBOT.to_model(), SHIFTED, detected, LEG, LEG)
    ghost = live.mode._ghost((detected,), 0)
    assert ghost.robot == truth.robot and climb.failure is None and live.mode.scene.ghost.visible
    np.testing.assert_allclose((ghost.clip.x[-1], ghost.clip.y[-1]), climb.states[1, :2] * L0, rtol=0, atol=1e-6 * L0)
    assert np.hypot(*(climb.states[1, :2] - paper.states[1, :2])) > 1e-3, "the paper's model lands elsewhere"
