"""Simulated runs as MCAP recordings (backend/services/mcap_sim.py), read back with the mcap reader
and mcap-protobuf-support and converted by Rerun's own importer: the body's path on a robot run's
channels and schemas, every sample of the stored path in metres, the run's touchdowns, the
simulation's metadata and, in a world, the world. Touchdown times are checked against sim_core's
own, which the store does not keep."""

from __future__ import annotations

import io
import json

import numpy as np
import pytest
from mcap.reader import make_reader
from mcap_protobuf.decoder import DecoderFactory
from numpy.testing import assert_allclose

from backend import errors
from backend.schemas.worlds import WorldCreate
from backend.services import worlds
from backend.services.mcap_export import METADATA_NAME, export_run
from backend.store.trajectory_blob import unpack_trajectory
from sim_core import ControlSchedule, get_preset, simulate_trajectory
from sim_core.world.files import world_from_document
from sim_core.world.trajectory import simulate_world_trajectory
from tests.backend.services.bodies import START
from tests.backend.services.test_mcap_export import exported, read, utc_ns
from tests.backend.services.test_mcap_visuals import component, rerun_entities
from tests.robot_runs import store_robot_run

RATE = 20.0  # samples per sqrt(l0/g)
ROBOT = get_preset("paper")
L0, T = ROBOT.scales.length, ROBOT.scales.time  # [m], [s]: a robot run's units
# The channels of a simulated run, in the order they are registered.
SIM_TOPICS = ["/tracker/pose", "/touchdowns", "/tracker/pose_in_frame", "/tracker/transform", "/tracker/body",
              "/world/scene", "/world/points", "/plot/height", "/plot/touchdown/body_height",
              "/plot/touchdown/foot_height", "/plot/touchdown/rise"]  # fmt: skip


def on(messages, topic: str) -> list[tuple[int, dict]]:
    return [(time, message) for name, _schema, time, message in messages if name == topic]


def reference_times(run) -> list[float]:
    """sim_core's touchdown times [sqrt(l0/g)] of ``run`` between parallel walls (the paper's model, START)."""
    model, schedule = get_preset("paper").to_model(), ControlSchedule.from_degrees(run.controls)
    path = simulate_trajectory(model, schedule, (START.xdot, START.ydot), run.jumps, sample_rate=RATE)
    return path.touchdown_times.tolist()


def test_a_simulated_run_is_a_robot_run_s_channels_holding_its_path(session, make_run):
    run = make_run(trajectory_rate=RATE, jumps=6)
    data, counts = exported(session, run.id)
    summary, metadata, messages, every = read(data)
    path, results = unpack_trajectory(run.trajectory), run.results
    samples, touchdowns = path["time"].size, len(results["states"])
    assert (samples, touchdowns) == (138, 7)

    topics = {channel.id: channel.topic for channel in summary.channels.values()}
    assert list(topics.values()) == SIM_TOPICS, "no commands, telemetry, link, log or prediction"
    assert counts == {topic: {"/world/scene": 1, "/world/points": 1, "/touchdowns": touchdowns,
                              "/plot/touchdown/body_height": touchdowns, "/plot/touchdown/foot_height": touchdowns,
                              "/plot/touchdown/rise": touchdowns - 1}.get(topic, samples)
                      for topic in SIM_TOPICS}  # fmt: skip
    assert {topics[i]: n for i, n in summary.statistics.channel_message_counts.items()} == counts
    robot = make_reader(io.BytesIO(exported(session, store_robot_run(session))[0])).get_summary()

    def schemas(of) -> dict[str, tuple[str, str, str]]:
        return {c.topic: (c.message_encoding, of.schemas[c.schema_id].encoding, of.schemas[c.schema_id].name)
                for c in of.channels.values()}  # fmt: skip

    assert schemas(summary) == {topic: schemas(robot)[topic] for topic in SIM_TOPICS}, "a robot run's schemas"
    times = [time for _topic, time in every]
    assert times == sorted(times), "written in log-time order"

    start = utc_ns(run.created_at)
    poses = on(messages, "/tracker/pose")
    assert [pose["tracker_time"] for _, pose in poses] == (path["time"] * T).tolist(), "every sample, in seconds"
    assert [pose["x"] for _, pose in poses] == (path["x"] * L0).tolist(), "exact: the stored path times l0"
    assert [pose["y"] for _, pose in poses] == (path["y"] * L0).tolist()
    assert not [pose for _, pose in poses if "pitch" in pose], "a point body: no pitch"
    assert [time for time, _ in poses] == [start + round(t * T * 1e9) for t in path["time"]]
    assert poses[0] == (start, {"tracker_time": 0.0, "x": pytest.approx(-0.27 + 0.9 * L0 * np.cos(np.pi / 6)),
                                "y": 0.0}), "touchdown 0 at the run's start, its body at height 0"  # fmt: skip

    found = on(messages, "/touchdowns")
    assert [td["index"] for _, td in found] == list(range(touchdowns))
    assert [td["state"] for _, td in found] == results["states"], "the map's section states"
    assert [td["rise"] for _, td in found[1:]] == results["rises"] and "rise" not in found[0][1]
    assert [td["wall"] for _, td in found] == [-1, 1] * 3 + [-1]
    assert all(td["control"] == {"psi0_deg": 30.0, "zeta0": 0.9} and td["poses_fitted"] == 0 for _, td in found)
    lift = 0.9 * np.sin(np.radians(30.0)) * L0
    assert [td["body_height"] - td["foot_height"] for _, td in found] == pytest.approx([lift] * touchdowns)
    feet = np.cumsum([0.0, *results["rises"]]) * L0 - lift
    assert [td["foot_height"] for _, td in found] == pytest.approx(feet.tolist(), abs=1e-12)
    stance = [int(np.flatnonzero((path["jump"] == k) & (path["phase"] == 0))[0]) for k in range(touchdowns - 1)]
    assert [td["foot_height"] for _, td in found[:-1]] == pytest.approx((path["foot_y"][stance] * L0).tolist(),
                                                                         abs=1e-12), "the path's feet"  # fmt: skip
    # At its stance's first sample: at most a sample period after sim_core's touchdown.
    late = [td["tracker_time"] / T - exact for (_, td), exact in zip(found, reference_times(run), strict=True)]
    assert late[0] == 0.0 and all(0.0 <= lag < 1 / RATE for lag in late), late
    assert [time for time, _ in found] == [start + round(td["tracker_time"] * 1e9) for _, td in found]

    about = metadata[METADATA_NAME]
    assert (about["run_id"], about["kind"], about["status"]) == (str(run.id), "sim", "done")
    assert json.loads(about["model"]) == run.model and json.loads(about["controls"]) == [[30.0, 0.9]]
    assert about["code_version"] == run.code_version and json.loads(about["start_state"]) == [-0.93, -0.17]
    assert json.loads(about["scales"]) == {"preset": "paper", "l0_m": L0, "time_s": T}
    assert (json.loads(about["failure"]), json.loads(about["world_id"]), json.loads(about["jumps"])) == (None, None, 6)
    assert about["time_convention"].startswith("log time = publish time = UTC ns: created_at + t")
    assert not {"calibration", "end_reason", "tracker", "prediction_model"} & set(about), "a robot's only"


@pytest.fixture
def sim_in_world(session, make_run):
    """A simulated run of 8 jumps in the named staircase, which slips at jump 6, and its world."""
    world = worlds.create(session, WorldCreate(name="staircase", named="staircase"))
    return make_run(trajectory_rate=RATE, jumps=8, world_id=world.id), world


def test_a_simulated_run_in_a_world_has_the_world_and_its_touchdowns(session, sim_in_world):
    run, world = sim_in_world
    data, counts = exported(session, run.id)
    _summary, metadata, messages, _every = read(data)
    stored = run.results["touchdowns"]
    assert len(stored) == counts["/touchdowns"] == 6 and run.results["failure"] == {"code": "slip", "jump": 6}

    found = on(messages, "/touchdowns")
    assert [td["body_height"] for _, td in found] == [td["y"] * L0 for td in stored], "the body's height, exact"
    assert [td["wall"] for _, td in found] == [-1 if td["side"] == "left" else 1 for td in stored]
    assert [td["rise"] for _, td in found[1:]] == run.results["rises"]
    shape = world_from_document(world.world, L0)
    path, _climb = simulate_world_trajectory(get_preset("paper").to_model(), shape,
                                             ControlSchedule.from_degrees(run.controls), (START.xdot, START.ydot),
                                             run.jumps, sample_rate=RATE)  # fmt: skip
    assert [td["state"] for _, td in found] == path.section_states.tolist(), "flipped to the left wall, as sim_core"
    assert [td["foot_height"] / L0 for _, td in found] == pytest.approx(np.cumsum([0.0, *path.rises]).tolist())
    late = [td["tracker_time"] / T - exact for (_, td), exact in zip(found, path.touchdown_times, strict=True)]
    assert all(0.0 <= lag < 1 / RATE for lag in late), late
    stored_path = unpack_trajectory(run.trajectory)
    assert [pose["y"] for _, pose in on(messages, "/tracker/pose")] == (stored_path["y"] * L0).tolist()
    assert json.loads(metadata[METADATA_NAME]["world_id"]) == world.id

    reader = make_reader(io.BytesIO(data), decoder_factories=[DecoderFactory()])
    topics = ["/world/scene", "/world/points"]
    drawn = {channel.topic: value for _s, channel, _m, value in reader.iter_decoded_messages(topics=topics)}
    labels = {pair.value for side in drawn["/world/scene"].entities for pair in side.metadata if pair.key == "world"}
    assert labels == {f"staircase (world {world.id})"}
    cloud = np.frombuffer(drawn["/world/points"].data, np.dtype([("x", "<f8"), ("y", "<f8"), ("z", "<f8"),
                                                                  ("rgba", "u1", 4)]))  # fmt: skip
    xz = np.column_stack([cloud["x"], cloud["z"]])
    for side in (shape.left, shape.right):
        for vertex in side.points * L0:
            assert np.min(np.hypot(*(xz - vertex).T)) < 1e-12, f"world vertex {vertex} [m] is a point"


def test_rerun_reads_a_simulated_run_in_a_world(session, sim_in_world, tmp_path):
    run, _world = sim_in_world
    data, _counts = exported(session, run.id)
    entities = rerun_entities(data, tmp_path)
    listed = sorted(path for path in entities if not path.startswith("/__mcap_"))
    assert listed == sorted(SIM_TOPICS), "the entities: one per channel"
    ((about,),) = component(entities["/__mcap_metadata"], "parkourlab.run")
    assert {pair["first"]: pair["second"] for pair in about}["kind"] == "sim", "Rerun shows the metadata too"
    path = unpack_trajectory(run.trajectory)
    positions = np.column_stack([path["x"] * L0, np.zeros(path["x"].size), path["y"] * L0])
    translations = [value for (value,) in component(entities["/tracker/transform"], "Transform3D:translation")]
    assert_allclose(translations, positions, rtol=1e-6, atol=1e-7, err_msg="the body in the chute [m]")
    points = [value for (value,) in component(entities["/tracker/body"], "Points3D:positions")]
    assert_allclose(points, positions, rtol=1e-6, atol=1e-7)
    assert [value for (value,) in component(entities["/plot/height"], "Scalars:scalars")] == positions[:, 2].tolist()
    rises = [value for (value,) in component(entities["/plot/touchdown/rise"], "Scalars:scalars")]
    assert rises == run.results["rises"]
    touchdowns = component(entities["/touchdowns"], "parkourlab.Touchdown:message")
    assert [message["index"] for (message,) in touchdowns] == list(range(6))
    assert component(entities["/world/points"], "CoordinateFrame:frame") == [["chute"]]


def test_a_simulated_run_without_its_path_is_refused(session, make_run):
    run = make_run()
    with pytest.raises(errors.Conflict, match=f"run {run.id} is a sim run stored without its path"):
        export_run(session, run.id, io.BytesIO())
