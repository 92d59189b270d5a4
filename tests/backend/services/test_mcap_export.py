"""Robot and replay runs as MCAP recordings, read back with the mcap reader (backend/services/mcap_export.py).
The channels drawn in Foxglove's and Rerun's formats are read in test_mcap_visuals.py."""

import datetime
import io
import json
import math

import pytest
from mcap.reader import make_reader

from backend import errors
from backend.repositories import runs as run_store
from backend.robot.tracker import Calibration
from backend.services import runs
from backend.services.mcap_export import METADATA_NAME, export_run
from backend.services.mcap_schemas import CHANNELS
from backend.services.mcap_visuals import PROTOBUF_CHANNELS, SERIES, SERIES_SCHEMA
from backend.services.robot_records import open_robot_run, replay_run
from backend.store.trajectory_blob import unpack_trajectory
from sim_core import get_preset
from tests.robot_runs import REQUEST, TRACKER_EPOCH, store_robot_run

JSON_TYPES = {"object": dict, "array": list, "string": str, "integer": int, "number": (int, float), "null": type(None)}


def check(value, schema: dict, where: str = "$") -> None:
    """``value`` against the JSON Schema keywords the channels use (type, required, properties,
    items, minItems, maxItems, enum, minimum, maximum); an AssertionError names the place."""
    types = schema.get("type", [])
    for name in [types] if isinstance(types, str) else types:
        if isinstance(value, JSON_TYPES[name]) and not (isinstance(value, bool) and name != "boolean"):
            break
    else:
        assert not types, f"{where}: {value!r} is not {types}"
    assert "enum" not in schema or value in schema["enum"], f"{where}: {value!r} not in {schema['enum']}"
    if isinstance(value, int | float) and not isinstance(value, bool):
        assert math.isfinite(value), where
        assert value >= schema.get("minimum", -math.inf) and value <= schema.get("maximum", math.inf), where
    if isinstance(value, dict):
        missing = set(schema.get("required", ())) - set(value)
        assert not missing, f"{where}: missing {sorted(missing)}"
        for key, item in value.items():
            check(item, schema.get("properties", {}).get(key, {}), f"{where}.{key}")
    if isinstance(value, list):
        assert schema.get("minItems", 0) <= len(value) <= schema.get("maxItems", math.inf), where
        for i, item in enumerate(value):
            check(item, schema.get("items", {}), f"{where}[{i}]")


def read(data: bytes):
    """(summary, metadata by name, [(topic, schema dict, log time, message dict)] of the JSON
    channels in file order, [(topic, log time)] of every message in file order)."""
    reader = make_reader(io.BytesIO(data))
    summary = reader.get_summary()
    metadata = {record.name: record.metadata for record in make_reader(io.BytesIO(data)).iter_metadata()}
    every = list(make_reader(io.BytesIO(data)).iter_messages(log_time_order=False))
    messages = [
        (channel.topic, json.loads(schema.data), message.log_time, json.loads(message.data))
        for schema, channel, message in every
        if channel.message_encoding == "json"
    ]
    return summary, metadata, messages, [(channel.topic, message.log_time) for _s, channel, message in every]


def exported(session, run_id: int) -> tuple[bytes, dict]:
    stream = io.BytesIO()
    counts = export_run(session, run_id, stream)
    return stream.getvalue(), counts


def utc_ns(moment: datetime.datetime) -> int:
    aware = moment if moment.tzinfo else moment.replace(tzinfo=datetime.UTC)
    return round(aware.timestamp() * 1e6) * 1000


def test_a_robot_run_reads_back_channel_by_channel(session):
    run = run_store.get_run(session, store_robot_run(session))
    data, counts = exported(session, run.id)
    summary, metadata, messages, every = read(data)

    frames = unpack_trajectory(run.trajectory)
    results = run.results
    expected = {
        "/tracker/pose": frames["time"].size,
        "/touchdowns": len(results["touchdowns"]),
        "/commands": len(results["commands"]),
        "/telemetry": len(results["telemetry"]),
        "/model/prediction": len(results["prediction"]["states"]),
        "/robot/link": len(results["transitions"]),
        **dict.fromkeys(PROTOBUF_CHANNELS, frames["time"].size),
        "/plot/height": frames["time"].size,
        "/plot/touchdown/body_height": len(results["touchdowns"]),
        "/plot/touchdown/foot_height": len(results["touchdowns"]),
        "/plot/touchdown/rise": len(results["rises"]),
        "/plot/prediction/rise": len(results["prediction"]["rises"]),
    }
    assert expected == {"/tracker/pose": 336, "/touchdowns": 5, "/commands": 3, "/telemetry": 6,
                        "/model/prediction": 5, "/robot/link": 1, "/tracker/pose_in_frame": 336,
                        "/tracker/transform": 336, "/tracker/body": 336, "/plot/height": 336,
                        "/plot/touchdown/body_height": 5, "/plot/touchdown/foot_height": 5, "/plot/touchdown/rise": 4,
                        "/plot/prediction/rise": 4}  # fmt: skip
    assert counts == expected
    topics = {channel.id: channel.topic for channel in summary.channels.values()}
    assert list(topics.values()) == [*CHANNELS, *PROTOBUF_CHANNELS, *SERIES]
    assert {topics[i]: n for i, n in summary.statistics.channel_message_counts.items()} == expected
    assert {topic: sum(1 for m in every if m[0] == topic) for topic in expected} == expected
    for channel in summary.channels.values():
        schema = summary.schemas[channel.schema_id]
        if channel.topic in CHANNELS:
            assert (channel.message_encoding, schema.encoding) == ("json", "jsonschema")
            assert json.loads(schema.data) == CHANNELS[channel.topic]
        elif channel.topic in PROTOBUF_CHANNELS:
            assert (channel.message_encoding, schema.encoding) == ("protobuf", "protobuf")
            assert schema.name == PROTOBUF_CHANNELS[channel.topic].DESCRIPTOR.full_name
        else:
            assert (channel.message_encoding, schema.encoding) == ("cdr", "ros2msg")
            assert schema.name == SERIES_SCHEMA == "std_msgs/msg/Float64MultiArray"
    for topic, schema, _time, message in messages:
        check(message, schema, topic)
    times = [time for _topic, time in every]
    assert times == sorted(times), "written in log-time order"

    def on(topic: str) -> list[tuple[int, dict]]:
        return [(time, message) for name, _schema, time, message in messages if name == topic]

    poses = on("/tracker/pose")
    start = utc_ns(run.created_at)
    assert poses[0][0] == start and poses[0][1]["tracker_time"] == pytest.approx(TRACKER_EPOCH)
    assert [pose["y"] for _, pose in poses] == pytest.approx(frames["y"].tolist())
    assert poses[7][1]["pitch"] is None and poses[1][1]["pitch"] == pytest.approx(0.02)
    later = poses[100]
    assert later[0] - start == pytest.approx((later[1]["tracker_time"] - TRACKER_EPOCH) * 1e9, abs=1)
    touchdowns = on("/touchdowns")
    assert [td["index"] for _, td in touchdowns] == [0, 1, 2, 3, 4]
    assert [td["control"]["zeta0"] for _, td in touchdowns] == [0.9, 0.87, 0.9, 0.87, 0.9]
    assert [td["rise"] for _, td in touchdowns[1:]] == pytest.approx(results["rises"])
    assert touchdowns[0][1]["rise"] is None
    predictions = on("/model/prediction")
    assert [time for time, _ in predictions] == [time for time, _ in touchdowns], "beside the measured touchdowns"
    assert [p["state"] for _, p in predictions] == results["prediction"]["states"]
    assert [p["measured_state"] for _, p in predictions] == [td["state"] for _, td in touchdowns]
    assert [time for time, _ in on("/commands")] == [round(c["time"] * 1e9) for c in results["commands"]]
    assert on("/telemetry")[0][1]["battery_mv"] == 7400 and on("/robot/link")[0][1]["to"] == "armed"

    about = metadata[METADATA_NAME]
    assert (about["run_id"], about["kind"], about["status"], about["end_reason"]) == (str(run.id), "robot", "done",
                                                                                       "jumps done")  # fmt: skip
    assert json.loads(about["model"]) == run.model and json.loads(about["controls"]) == run.controls
    assert json.loads(about["calibration"])["scale"] == 1.0 and about["code_version"] == run.code_version
    assert json.loads(about["source_run_id"]) is None and json.loads(about["tracker"])["frames"] == 336


def test_a_replay_is_its_source_s_recording_with_its_own_touchdowns(session):
    source = run_store.get_run(session, store_robot_run(session))
    replay = replay_run(session, source.id)
    data, counts = exported(session, replay.id)
    _summary, metadata, messages, _every = read(data)
    assert counts["/tracker/pose"] == unpack_trajectory(source.trajectory)["time"].size
    assert counts["/touchdowns"] == len(replay.results["touchdowns"]) == 5
    assert counts["/model/prediction"] == len(replay.results["prediction"]["states"])
    assert counts["/commands"] == len(source.results["commands"]) and counts["/robot/link"] == 1
    first_pose = next(time for topic, _s, time, _m in messages if topic == "/tracker/pose")
    assert first_pose == utc_ns(source.created_at), "on the source's clock: when it was recorded"
    controls = [m["control"]["zeta0"] for topic, _s, _t, m in messages if topic == "/touchdowns"]
    assert controls == [0.9, 0.87, 0.9, 0.87, 0.9]
    about = metadata[METADATA_NAME]
    assert (about["kind"], json.loads(about["source_run_id"])) == ("replay", source.id)


def test_runs_that_are_no_recordings_are_refused(session, make_run):
    simulated = make_run()
    with pytest.raises(errors.Conflict, match="sim run: only robot and replay runs are recordings"):
        export_run(session, simulated.id, io.BytesIO())
    running = open_robot_run(session, REQUEST, get_preset("paper"), Calibration())
    with pytest.raises(errors.Conflict, match="still running"):
        export_run(session, running, io.BytesIO())
    with pytest.raises(errors.NotFound, match="run 999 does not exist"):
        export_run(session, 999, io.BytesIO())
    source = store_robot_run(session)
    replay = replay_run(session, source)
    runs.delete(session, source)
    with pytest.raises(errors.Conflict, match=f"source run {source} is gone"):
        export_run(session, replay.id, io.BytesIO())
