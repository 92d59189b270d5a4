"""The chute in a run's MCAP recording (backend/services/mcap_world.py): a stored world's sides as
Foxglove ``SceneUpdate`` entities and a coloured ``PointCloud``, read back by mcap-protobuf-support
(positions in metres against the world file) and by Rerun's own importer; a run without a world
draws the parallel walls it climbed.

The robot run of tests/robot_runs.py climbed parallel walls in the simulator; here it is stored as
having climbed :data:`WORLD` (``runs.world_id`` set as a robot run in a world will have it): what is
checked is the drawing of the world, not the climb."""

from __future__ import annotations

import io
import json
import math

import numpy as np
import pytest
from mcap.reader import make_reader
from mcap_protobuf.decoder import DecoderFactory
from numpy.testing import assert_allclose

from backend.repositories import runs as run_store
from backend.schemas.worlds import WorldCreate
from backend.services import mcap_world as drawn
from backend.services import worlds
from backend.services.mcap_export import export_run
from backend.services.mcap_world import mu_color
from backend.services.robot_records import replay_run
from backend.store.trajectory_blob import unpack_trajectory
from sim_core.model.presets import get_preset
from tests.backend.services.test_mcap_visuals import component, rerun_entities
from tests.robot_runs import store_robot_run

# A lab wall in metres: on the left a ledge without grip, a foothold leaning out (it faces up),
# again no grip, then the model's mu; on the right no slip, then mu 1.5.
WORLD = {
    "units": "m",
    "left": {"points": [[-0.27, 0.0], [-0.27, 0.3], [-0.31, 0.36], [-0.27, 0.42], [-0.27, 2.0]],
             "mu": [0.0, 0.8, 0.0, None]},
    "right": {"points": [[0.27, 0.0], [0.27, 1.0], [0.27, 2.0]], "mu": ["inf", 1.5]},
}  # fmt: skip
MU = {"left": [0.0, 0.8, 0.0, math.nan], "right": [math.inf, 1.5]}
L0 = get_preset("paper").leg_length
POINT = np.dtype([("x", "<f8"), ("y", "<f8"), ("z", "<f8"), ("red", "u1"), ("green", "u1"), ("blue", "u1"),
                  ("alpha", "u1")])  # fmt: skip


@pytest.fixture
def run_in_world(session):
    """A robot run stored as climbing :data:`WORLD` (its id) and the world's id."""
    world = worlds.create(session, WorldCreate(name="lab wall", world=WORLD))
    run = run_store.get_run(session, store_robot_run(session))
    run.world_id = world.id
    session.commit()
    return run.id, world.id


def exported(session, run_id: int) -> bytes:
    stream = io.BytesIO()
    export_run(session, run_id, stream)
    return stream.getvalue()


def world_messages(data: bytes) -> tuple[int, dict[str, list[tuple[int, object]]]]:
    """(the recording's first log time, {topic: [(log time, decoded message)]} of /world/*)."""
    reader = make_reader(io.BytesIO(data), decoder_factories=[DecoderFactory()])
    found: dict[str, list] = {}
    for _schema, channel, message, value in reader.iter_decoded_messages(topics=["/world/scene", "/world/points"]):
        found.setdefault(channel.topic, []).append((message.log_time, value))
    return make_reader(io.BytesIO(data)).get_summary().statistics.message_start_time, found


def rotated(q, v: tuple[float, float, float]) -> np.ndarray:
    """``v`` turned by the unit quaternion ``q``."""
    u, w = np.array([q.x, q.y, q.z]), q.w
    return 2 * np.dot(u, v) * u + (w * w - np.dot(u, u)) * np.array(v) + 2 * w * np.cross(u, v)


def rgba(color) -> tuple[int, int, int, float]:
    return round(color.r * 255), round(color.g * 255), round(color.b * 255), color.a


def test_a_world_s_sides_are_scene_entities_of_slabs_in_metres_once_at_the_start(session, run_in_world):
    run_id, world_id = run_in_world
    start, messages = world_messages(exported(session, run_id))
    ((time, update),) = messages["/world/scene"]
    assert time == start, "at the recording's start"
    assert [entity.id for entity in update.entities] == ["left", "right"] and not update.deletions
    for entity in update.entities:
        side, points = entity.id, np.array(WORLD[entity.id]["points"])
        assert entity.frame_id == "chute" and entity.frame_locked and not entity.HasField("lifetime"), "it stays"
        assert entity.timestamp.ToNanoseconds() == start
        metadata = {pair.key: pair.value for pair in entity.metadata}
        assert metadata["side"] == side and metadata["world"] == f"lab wall (world {world_id})"
        assert json.loads(metadata["mu"]) == WORLD[side]["mu"]
        assert json.loads(metadata["footholds"]) == [k for k, mu in enumerate(MU[side]) if mu != 0]
        (line,) = entity.lines
        assert_allclose([(p.x, p.y, p.z) for p in line.points], np.insert(points, 1, 0.0, axis=1), rtol=0, atol=1e-15)
        assert len(entity.cubes) == len(points) - 1, "a slab per segment"
        for k, (cube, mu) in enumerate(zip(entity.cubes, MU[side], strict=True)):
            a, b = points[k], points[k + 1]
            along, length = (b - a) / np.hypot(*(b - a)), np.hypot(*(b - a))
            inward = np.array([along[1], -along[0]]) * (1 if side == "left" else -1)
            q, c = cube.pose.orientation, cube.pose.position
            assert_allclose(rotated(q, (0, 0, 1)), (along[0], 0, along[1]), atol=1e-15, err_msg="local z along it")
            thickness = drawn.NO_GRIP if mu == 0 else drawn.FOOTHOLD
            assert (cube.size.x, cube.size.y) == (thickness, drawn.DEPTH)
            assert cube.size.z == pytest.approx(length, abs=1e-15), "as long as the segment"
            face = np.array([c.x, c.z]) + inward * thickness / 2  # the face toward the chute
            assert_allclose(face, (a + b) / 2, atol=1e-15, err_msg=f"{side} segment {k}: its face on the segment")
            assert c.y == 0.0
            assert rgba(cube.color) == (*mu_color(mu), drawn.NO_GRIP_ALPHA if mu == 0 else 1.0), f"{side} segment {k}"
    left, right = update.entities
    assert rgba(left.cubes[0].color)[:3] == drawn.STOPS[0][1], "no grip: the scale's lightest"
    assert rgba(left.cubes[3].color)[:3] == drawn.MODEL_MU_RGB and rgba(right.cubes[0].color)[:3] == drawn.NO_SLIP_RGB


def test_the_points_trace_the_same_sides_in_their_colours(session, run_in_world):
    run_id, _ = run_in_world
    start, messages = world_messages(exported(session, run_id))
    ((time, cloud),) = messages["/world/points"]
    assert time == start == cloud.timestamp.ToNanoseconds() and cloud.frame_id == "chute"
    assert [(f.name, f.offset) for f in cloud.fields] == [(name, POINT.fields[name][1]) for name in POINT.names]
    points = np.frombuffer(cloud.data, POINT)
    assert cloud.point_stride == POINT.itemsize == 28 and np.all(points["y"] == 0.0)
    xz = np.column_stack([points["x"], points["z"]])
    for side in ("left", "right"):
        for vertex in WORLD[side]["points"]:
            assert np.min(np.hypot(*(xz - vertex).T)) < 1e-15, f"{side} vertex {vertex} is a point"
    # the leaning foothold, its start on the wall line and its top (the next segment's start) left out
    foothold = (points["x"] < -0.27) & (points["z"] < 0.36 - 1e-9)
    assert set(map(tuple, np.column_stack([points[c][foothold] for c in ("red", "green", "blue", "alpha")]))) == {
        (*mu_color(0.8), 255)
    }
    steps = np.diff(points["z"][(points["x"] == -0.27) & (points["z"] < 0.3)])
    assert_allclose(steps, 0.3 / 15, err_msg="a segment without grip is dotted every 2 cm")


def test_a_run_without_a_world_draws_its_parallel_walls(session):
    run = run_store.get_run(session, store_robot_run(session))
    highest = float(np.max(unpack_trajectory(run.trajectory)["y"]))
    _start, messages = world_messages(exported(session, run.id))
    ((_time, update),) = messages["/world/scene"]
    for entity, x in zip(update.entities, (-0.27, 0.27), strict=True):
        (line,) = entity.lines
        ends = [(p.x, p.z) for p in line.points]
        assert_allclose(ends, [(x, 0.0), (x, highest + L0)], rtol=0, atol=1e-15, err_msg="floor to l0 above the body")
        assert {pair.key: pair.value for pair in entity.metadata}["world"] == "parallel walls 0.54 m apart"
        (cube,) = entity.cubes
        assert rgba(cube.color) == (*drawn.MODEL_MU_RGB, 1.0), "the model's mu"


def test_a_replay_draws_its_source_s_world(session, run_in_world):
    run_id, world_id = run_in_world
    replay = replay_run(session, run_id)
    _start, messages = world_messages(exported(session, replay.id))
    ((_time, update),) = messages["/world/scene"]
    assert {pair.value for e in update.entities for pair in e.metadata if pair.key == "world"} == {
        f"lab wall (world {world_id})"
    }


def test_rerun_keeps_the_scene_as_a_struct_and_draws_the_points(session, run_in_world, tmp_path):
    """Rerun 0.41's importer has no SceneUpdate decoder: /world/scene is one entity holding the
    message as a struct (the sides' entities inside it); /world/points is drawn as coloured Points3D."""
    run_id, _ = run_in_world
    data = exported(session, run_id)
    start, messages = world_messages(data)
    entities = rerun_entities(data, tmp_path)
    assert sorted(path for path in entities if path.startswith("/world")) == ["/world/points", "/world/scene"]

    (scene,) = component(entities["/world/scene"], "foxglove.SceneUpdate:message")
    assert component(entities["/world/scene"], "message_log_time") == [start]
    (update,) = scene
    assert [entity["id"] for entity in update["entities"]] == ["left", "right"]
    assert all(entity["frame_id"] == "chute" and entity["frame_locked"] for entity in update["entities"])
    left = update["entities"][0]
    assert_allclose([(p["x"], p["z"]) for p in left["lines"][0]["points"]], WORLD["left"]["points"], rtol=0, atol=1e-15)
    ((_, decoded),) = messages["/world/scene"]
    slabs = decoded.entities[0].cubes
    assert [cube["pose"]["position"]["x"] for cube in left["cubes"]] == [cube.pose.position.x for cube in slabs]

    assert component(entities["/world/points"], "CoordinateFrame:frame") == [["chute"]]
    (positions,) = component(entities["/world/points"], "Points3D:positions")
    (colors,) = component(entities["/world/points"], "Points3D:colors")
    ((_, cloud),) = messages["/world/points"]
    points = np.frombuffer(cloud.data, POINT)
    assert_allclose(positions, np.column_stack([points["x"], points["y"], points["z"]]), rtol=1e-6, atol=1e-7)
    channels = zip(points["red"], points["green"], points["blue"], points["alpha"], strict=True)
    packed = [(int(r) << 24) | (int(g) << 16) | (int(b) << 8) | int(a) for r, g, b, a in channels]
    assert colors == packed, "RGBA, one u32 each"


def test_friction_is_coloured_on_the_panel_s_scale():
    """frontend/panel/world_draw.js's muColor: reversed viridis over mu 0..3, grey the model's, black no slip."""
    at_stops = [mu_color(mu) for mu in (0.0, 0.75, 1.5, 2.25, 3.0, 9.0)]
    assert at_stops == [stop for _, stop in drawn.STOPS] + [(68, 1, 84)], "mu 3 and above: the darkest"
    assert mu_color(0.375) == (174, 216, 68), "halfway between the first two stops"
    assert (mu_color(math.nan), mu_color(math.inf)) == ((154, 154, 154), (17, 17, 17))
