"""The channels of a run's MCAP recording that Foxglove and Rerun draw (backend/services/mcap_visuals.py),
read back three ways: protobuf decoded by mcap-protobuf-support, the ROS 2 arrays by
mcap-ros2-support, and the whole file by Rerun's own MCAP importer (``rerun mcap convert`` with its
default decoders), each compared with the run's frames, touchdowns and prediction. Rerun shows the
run's own channels (backend/services/mcap_schemas.py) field by field too, on the tracker's clock."""

from __future__ import annotations

import io
import math
import os
import struct
import subprocess
import sys
from collections import defaultdict

import numpy as np
import pyarrow as pa
import pytest
from google.protobuf.json_format import MessageToDict
from mcap.reader import make_reader
from mcap_protobuf.decoder import DecoderFactory as ProtobufDecoders
from mcap_ros2.decoder import DecoderFactory as Ros2Decoders
from numpy.testing import assert_allclose
from rerun.chunk import RrdReader

from backend.repositories import runs as run_store
from backend.services.mcap_export import export_run
from backend.services.mcap_schemas import TOPICS
from backend.services.mcap_visuals import PROTOBUF_CHANNELS, SERIES, series_cdr
from backend.services.robot_records import replay_run
from backend.store.trajectory_blob import unpack_trajectory
from tests.robot_runs import store_lagging_run, store_robot_run

RTOL_F32 = 1e-6  # Rerun keeps positions and quaternions as float32
ATOL_F32 = 1e-7  # [m] near zero
PITCH = 0.02  # [rad] the pitch tests/robot_runs.py gives the frames it does not leave untracked
BODY_CHANNELS = ("/tracker/pose_in_frame", "/tracker/transform", "/tracker/body")  # one message per frame


@pytest.fixture
def run_and_recording(session):
    """A stored robot run (5 touchdowns, 336 frames) and its MCAP as bytes."""
    run = run_store.get_run(session, store_robot_run(session))
    stream = io.BytesIO()
    export_run(session, run.id, stream)
    return run, stream.getvalue()


def decoded(data: bytes) -> dict[str, list[tuple[int, object]]]:
    """topic -> [(log time, decoded message)] in log-time order: protobuf and ROS 2 channels
    decoded by their MCAP support libraries; the run's own channels as dicts of their fields (an
    absent one: None)."""
    reader = make_reader(io.BytesIO(data), decoder_factories=[ProtobufDecoders(), Ros2Decoders()])
    messages = defaultdict(list)
    for _schema, channel, message, value in reader.iter_decoded_messages(log_time_order=True):
        messages[channel.topic].append((message.log_time, fields(value) if channel.topic in TOPICS else value))
    return messages


def fields(message) -> dict:
    """A protobuf message's fields as Rerun shows them: each by name, None where absent (an empty list too)."""
    present = MessageToDict(message, preserving_proto_field_name=True, always_print_fields_with_no_presence=True)
    return {field.name: None if present.get(field.name) == [] else present.get(field.name)
            for field in message.DESCRIPTOR.fields}  # fmt: skip


def expected_orientation(pitch: float | None) -> tuple[float, float, float, float]:
    """(x, y, z, w): the pitch (none: level) as a turn about -y."""
    half = 0.5 * (0.0 if pitch is None else pitch)
    return (0.0, -math.sin(half), 0.0, math.cos(half))


def test_the_body_is_foxglove_s_pose_transform_and_point_in_protobuf(run_and_recording):
    run, data = run_and_recording
    messages = decoded(data)
    frames = unpack_trajectory(run.trajectory)
    poses = messages["/tracker/pose"]
    assert len(poses) == frames["time"].size == 336
    for topic in BODY_CHANNELS:
        assert [time for time, _ in messages[topic]] == [time for time, _ in poses], topic

    for (time, pose), (_, framed), (_, transform), (_, cloud) in zip(
        poses, messages["/tracker/pose_in_frame"], messages["/tracker/transform"], messages["/tracker/body"],
        strict=True,
    ):  # fmt: skip
        where = f"frame at tracker time {pose['tracker_time']}"
        position = (pose["x"], 0.0, pose["y"])
        orientation = expected_orientation(pose["pitch"])
        assert framed.timestamp.ToNanoseconds() == transform.timestamp.ToNanoseconds() == time, where
        assert framed.frame_id == transform.parent_frame_id == cloud.frame_id == "chute", where
        assert transform.child_frame_id == "body", where
        p, q = framed.pose.position, framed.pose.orientation
        assert (p.x, p.y, p.z) == position and (q.x, q.y, q.z, q.w) == pytest.approx(orientation, abs=1e-15), where
        t, r = transform.translation, transform.rotation
        assert (t.x, t.y, t.z) == position and (r.x, r.y, r.z, r.w) == (q.x, q.y, q.z, q.w), where
        fields = [(field.name, field.offset, field.type) for field in cloud.fields]
        assert fields == [("x", 0, 8), ("y", 8, 8), ("z", 16, 8)] and cloud.point_stride == 24, "float64 x, y, z"
        assert struct.unpack("<3d", cloud.data) == position, where
        assert cloud.pose.HasField("position") and cloud.pose.orientation.w == 1.0, "the cloud at the origin"
    assert_allclose([m.pose.position.z for _, m in messages["/tracker/pose_in_frame"]], frames["y"], rtol=0)


def test_the_pose_in_frame_keeps_the_tracker_pose_up_on_z(run_and_recording):
    """Nothing of /tracker/pose (the wall's x and y up) is lost in Foxglove's frame (x and z up)."""
    _run, data = run_and_recording
    messages = decoded(data)
    (_, tracked), (_, framed) = messages["/tracker/pose"][1], messages["/tracker/pose_in_frame"][1]
    assert (framed.pose.position.x, framed.pose.position.z) == (tracked["x"], tracked["y"])
    q = framed.pose.orientation
    # A counter-clockwise pitch (x right, up up) turns the body's x axis up: +z.
    x_axis = (1 - 2 * (q.y**2 + q.z**2), 2 * (q.x * q.y + q.w * q.z), 2 * (q.x * q.z - q.w * q.y))
    assert tracked["pitch"] == pytest.approx(PITCH)
    assert x_axis == pytest.approx((math.cos(PITCH), 0.0, math.sin(PITCH)))
    untracked = messages["/tracker/pose_in_frame"][7][1].pose.orientation
    assert messages["/tracker/pose"][7][1]["pitch"] is None
    assert (untracked.x, untracked.y, untracked.z, untracked.w) == (0.0, 0.0, 0.0, 1.0), "no pitch: level"


def test_the_series_are_ros2_arrays_of_the_run_s_numbers(run_and_recording):
    run, data = run_and_recording
    messages = decoded(data)
    frames = unpack_trajectory(run.trajectory)
    results = run.results

    def series(topic: str) -> list[float]:
        values = [message.data for _, message in messages[topic]]
        assert all(len(value) == 1 for value in values), f"{topic}: one number a message"
        return [value[0] for value in values]

    def times(topic: str) -> list[int]:
        return [time for time, _ in messages[topic]]

    assert series("/plot/height") == frames["y"].tolist()
    assert times("/plot/height") == times("/tracker/pose")
    assert series("/plot/touchdown/body_height") == [td["body_height"] for td in results["touchdowns"]]
    assert series("/plot/touchdown/foot_height") == [td["foot_height"] for td in results["touchdowns"]]
    assert times("/plot/touchdown/body_height") == times("/touchdowns")
    assert series("/plot/touchdown/rise") == results["rises"] and len(results["rises"]) == 4
    assert times("/plot/touchdown/rise") == times("/touchdowns")[1:], "from the second touchdown on"
    assert series("/plot/prediction/rise") == results["prediction"]["rises"]
    assert times("/plot/prediction/rise") == times("/model/prediction")[1:]


def test_a_series_message_is_28_bytes_of_little_endian_cdr():
    assert series_cdr(1.5) == b"\x00\x01\x00\x00" + struct.pack("<III4xd", 0, 0, 1, 1.5)
    assert len(series_cdr(-0.25)) == 28


def rerun_entities(data: bytes, tmp_path) -> dict[str, list[dict]]:
    """The recording converted by Rerun's importer with its default decoders, read back: entity
    path -> rows (component or timeline -> value; timelines as int ns), in log-time order."""
    mcap, rrd = tmp_path / "run.mcap", tmp_path / "run.rrd"
    mcap.write_bytes(data)
    # CI set: Rerun sends no usage data (and asks nothing on a first run).
    env = {**os.environ, "CI": "true"}
    convert = [sys.executable, "-m", "rerun_cli", "mcap", "convert", str(mcap), "-o", str(rrd)]
    subprocess.run(convert, check=True, capture_output=True, env=env, timeout=120)
    entities = defaultdict(list)
    for chunk in RrdReader(rrd).stream():
        batch = chunk.to_record_batch()
        columns = {}
        for field, column in zip(batch.schema, batch.columns, strict=True):
            if field.name.startswith("rerun.controls"):
                continue
            columns[field.name] = column.cast(pa.int64()) if pa.types.is_timestamp(field.type) else column
        entities[chunk.entity_path].extend(
            {name: column[i].as_py() for name, column in columns.items()} for i in range(batch.num_rows)
        )
    for rows in entities.values():
        rows.sort(key=lambda row: row.get("message_log_time", -1))
    return entities


def component(rows: list[dict], name: str) -> list:
    """The values of one component, in the rows that have it."""
    return [row[name] for row in rows if row.get(name) is not None]


def test_rerun_opens_the_recording_as_a_transform_points_and_plots(run_and_recording, tmp_path):
    run, data = run_and_recording
    frames = unpack_trajectory(run.trajectory)
    results = run.results
    entities = rerun_entities(data, tmp_path)
    positions = np.column_stack([frames["x"], np.zeros(frames["x"].size), frames["y"]])
    pitches = np.where(np.isnan(frames["pitch"]), 0.0, frames["pitch"])
    quaternions = np.column_stack([np.zeros_like(pitches), -np.sin(pitches / 2), np.zeros_like(pitches),
                                   np.cos(pitches / 2)])  # fmt: skip
    log_times = [time for time, _ in decoded(data)["/tracker/pose"]]

    transform = entities["/tracker/transform"]
    assert component(transform, "Transform3D:parent_frame") == [["chute"]] * 336
    assert component(transform, "Transform3D:child_frame") == [["body"]] * 336
    assert component(transform, "message_log_time") == log_times
    translations = [value for (value,) in component(transform, "Transform3D:translation")]
    assert_allclose(translations, positions, rtol=RTOL_F32, atol=ATOL_F32, err_msg="the body in the chute [m]")
    rotations = [value for (value,) in component(transform, "Transform3D:quaternion")]
    assert_allclose(rotations, quaternions, rtol=RTOL_F32, atol=ATOL_F32, err_msg="the pitch about -y")

    for topic in ("/tracker/pose_in_frame", "/tracker/body"):
        assert component(entities[topic], "CoordinateFrame:frame") == [["chute"]] * 336, topic
    posed = [value for (value,) in component(entities["/tracker/pose_in_frame"], "InstancePoses3D:translations")]
    assert_allclose(posed, positions, rtol=RTOL_F32, atol=ATOL_F32, err_msg="PoseInFrame as InstancePoses3D")
    points = [value for (value,) in component(entities["/tracker/body"], "Points3D:positions")]
    assert_allclose(points, positions, rtol=RTOL_F32, atol=ATOL_F32, err_msg="PointCloud as Points3D")

    def scalars(path: str) -> list[float]:
        values = component(entities[path], "Scalars:scalars")
        assert all(len(value) == 1 for value in values), path
        return [value for (value,) in values]

    assert scalars("/plot/height") == frames["y"].tolist(), "Scalars are float64: exact"
    assert component(entities["/plot/height"], "message_log_time") == log_times
    assert scalars("/plot/touchdown/body_height") == [td["body_height"] for td in results["touchdowns"]]
    assert scalars("/plot/touchdown/foot_height") == [td["foot_height"] for td in results["touchdowns"]]
    assert scalars("/plot/touchdown/rise") == results["rises"]
    assert scalars("/plot/prediction/rise") == results["prediction"]["rises"]

    drawn = {path for path, rows in entities.items() if any(name.startswith(("Scalars:", "Points3D:",
             "Transform3D:", "InstancePoses3D:", "TextLog:")) for row in rows for name in row)}  # fmt: skip
    # All but the SceneUpdate, which Rerun 0.41 keeps as a struct (tests/backend/services/test_mcap_world.py).
    assert drawn == {*PROTOBUF_CHANNELS, *SERIES} - {"/world/scene"}
    log = [text for (text,) in component(entities["/robot/log"], "TextLog:text")]
    assert log == [
        f"{c['leg']} leg psi0 {c['psi0_deg']:.3f} deg, zeta0 {c['zeta0']:.4f} l0: start"
        for c in results["commands"][:2]
    ] + ["link disarmed -> armed: arm", log[3]], "in the order they happened"
    assert component(entities["/robot/log"], "TextLog:level") == [["INFO"]] * 4


def test_rerun_shows_every_channel_of_the_run_field_by_field(run_and_recording, tmp_path):
    """Issue 40: the run's own channels were JSON, which Rerun 0.41 shows as each message's bytes."""
    _run, data = run_and_recording
    entities = rerun_entities(data, tmp_path)
    assert not [path for path, rows in entities.items() for row in rows if "McapMessage:data" in row], "no blobs"
    for topic, name in TOPICS.items():
        structs = [value for (value,) in component(entities[topic], f"parkourlab.{name}:message")]
        assert structs == [message for _, message in decoded(data)[topic]], topic
        assert component(entities[topic], "message_log_time") == [time for time, _ in decoded(data)[topic]], topic


def test_rerun_places_a_lagging_run_s_commands_at_the_frames_they_followed(session, tmp_path):
    """Frames at 0.37x real time: in Rerun's log-time timeline, each command and telemetry sits at
    the frame whose tracker time it carries, and the law's commands each after its touchdown."""
    stream = io.BytesIO()
    export_run(session, store_lagging_run(session), stream)
    entities = rerun_entities(stream.getvalue(), tmp_path)

    def timed(topic: str) -> list[tuple[int, dict]]:
        rows = [row for row in entities[topic] if row.get(f"parkourlab.{TOPICS[topic]}:message") is not None]
        return [(row["message_log_time"], row[f"parkourlab.{TOPICS[topic]}:message"][0]) for row in rows]

    frame_at = {pose["tracker_time"]: time for time, pose in timed("/tracker/pose")}
    stamped = [(time, record) for topic in ("/commands", "/telemetry") for time, record in timed(topic)
               if record["tracker_time"] is not None]  # fmt: skip
    assert len(stamped) > 150 and all(time == frame_at[record["tracker_time"]] for time, record in stamped)
    touchdowns = [time for time, _ in timed("/touchdowns")]
    law = [time for time, command in timed("/commands") if command["why"].startswith("pid after")]
    assert all(touchdown < time for touchdown, time in zip(touchdowns, law, strict=True))
    assert all(time < touchdown for time, touchdown in zip(law, touchdowns[1:], strict=False))


def test_a_replay_opens_in_rerun_with_its_own_touchdowns(session, tmp_path):
    source = store_robot_run(session)
    replay = replay_run(session, source)
    stream = io.BytesIO()
    export_run(session, replay.id, stream)
    entities = rerun_entities(stream.getvalue(), tmp_path)
    heights = [value for (value,) in component(entities["/plot/touchdown/body_height"], "Scalars:scalars")]
    assert heights == [td["body_height"] for td in replay.results["touchdowns"]]
    assert len(component(entities["/tracker/transform"], "Transform3D:translation")) == 336, "the source's frames"
