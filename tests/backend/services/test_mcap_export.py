"""Robot and replay runs as MCAP recordings, read back with the mcap reader and mcap-protobuf-support
(backend/services/mcap_export.py), and their clock: a lagging robot's commands, telemetry and link
changes among its frames. The channels drawn in Foxglove's and Rerun's formats are read in
test_mcap_visuals.py, simulated runs' recordings in test_mcap_sim.py."""

import datetime
import io
import json

import numpy as np
import pytest
from google.protobuf.json_format import MessageToDict
from mcap.reader import make_reader
from mcap_protobuf.decoder import DecoderFactory

from backend import errors
from backend.repositories import runs as run_store
from backend.robot.tracker import Calibration
from backend.services import runs
from backend.services.mcap_export import METADATA_NAME, export_run
from backend.services.mcap_schemas import TOPICS
from backend.services.mcap_visuals import PROTOBUF_CHANNELS, SERIES, SERIES_SCHEMA
from backend.services.robot_records import open_robot_run, replay_run
from backend.store.trajectory_blob import unpack_trajectory
from sim_core import get_preset
from tests.robot_runs import (
    DETECTED_AFTER,
    LAG_SPEED,
    REQUEST,
    TELEMETRY_EVERY,
    TRACKER_EPOCH,
    store_lagging_run,
    store_robot_run,
)

FRAME_PERIOD = 0.01  # [s] of tracker time: the 100 Hz frames of tests/robot_runs.py


def read(data: bytes):
    """(summary, metadata by name, [(topic, schema, log time, message as a dict of its fields)] of the
    run's own channels in file order, decoded by mcap-protobuf-support from the schemas in the file,
    [(topic, log time)] of every message in file order)."""
    reader = make_reader(io.BytesIO(data), decoder_factories=[DecoderFactory()])
    summary = reader.get_summary()
    metadata = {record.name: record.metadata for record in make_reader(io.BytesIO(data)).iter_metadata()}
    every = list(make_reader(io.BytesIO(data)).iter_messages(log_time_order=False))
    messages = [
        (channel.topic, schema, message.log_time, fields(decoded))
        for schema, channel, message, decoded in reader.iter_decoded_messages(topics=list(TOPICS), log_time_order=False)
    ]
    return summary, metadata, messages, [(channel.topic, message.log_time) for _s, channel, message in every]


def fields(message) -> dict:
    """A decoded message's fields, those with presence only when set; NaN as "NaN"."""
    return MessageToDict(message, preserving_proto_field_name=True, always_print_fields_with_no_presence=True)


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
        "/robot/log": len(results["transitions"]) + len(results["commands"]),
        "/world/scene": 1,
        "/world/points": 1,
        "/plot/height": frames["time"].size,
        "/plot/touchdown/body_height": len(results["touchdowns"]),
        "/plot/touchdown/foot_height": len(results["touchdowns"]),
        "/plot/touchdown/rise": len(results["rises"]),
        "/plot/prediction/rise": len(results["prediction"]["rises"]),
    }
    assert expected == {"/tracker/pose": 336, "/touchdowns": 5, "/commands": 3, "/telemetry": 6,
                        "/model/prediction": 5, "/robot/link": 1, "/tracker/pose_in_frame": 336,
                        "/tracker/transform": 336, "/tracker/body": 336, "/robot/log": 4, "/world/scene": 1,
                        "/world/points": 1, "/plot/height": 336,
                        "/plot/touchdown/body_height": 5, "/plot/touchdown/foot_height": 5, "/plot/touchdown/rise": 4,
                        "/plot/prediction/rise": 4}  # fmt: skip
    assert counts == expected
    topics = {channel.id: channel.topic for channel in summary.channels.values()}
    assert list(topics.values()) == [*TOPICS, *PROTOBUF_CHANNELS, *SERIES]
    assert {topics[i]: n for i, n in summary.statistics.channel_message_counts.items()} == expected
    assert {topic: sum(1 for m in every if m[0] == topic) for topic in expected} == expected
    for channel in summary.channels.values():
        schema = summary.schemas[channel.schema_id]
        if channel.topic in TOPICS:
            assert (channel.message_encoding, schema.encoding) == ("protobuf", "protobuf")
            assert schema.name == f"parkourlab.{TOPICS[channel.topic]}"
        elif channel.topic in PROTOBUF_CHANNELS:
            assert (channel.message_encoding, schema.encoding) == ("protobuf", "protobuf")
            assert schema.name == PROTOBUF_CHANNELS[channel.topic].DESCRIPTOR.full_name
        else:
            assert (channel.message_encoding, schema.encoding) == ("cdr", "ros2msg")
            assert schema.name == SERIES_SCHEMA == "std_msgs/msg/Float64MultiArray"
    times = [time for _topic, time in every]
    assert times == sorted(times), "written in log-time order"

    def on(topic: str) -> list[tuple[int, dict]]:
        return [(time, message) for name, _schema, time, message in messages if name == topic]

    poses = on("/tracker/pose")
    start = utc_ns(run.created_at)
    assert poses[0][0] == start and poses[0][1]["tracker_time"] == pytest.approx(TRACKER_EPOCH)
    assert [pose["y"] for _, pose in poses] == pytest.approx(frames["y"].tolist())
    assert "pitch" not in poses[7][1] and poses[1][1]["pitch"] == pytest.approx(0.02), "an untracked pitch: absent"
    later = poses[100]
    assert later[0] - start == pytest.approx((later[1]["tracker_time"] - TRACKER_EPOCH) * 1e9, abs=1)
    touchdowns = on("/touchdowns")
    assert [td["index"] for _, td in touchdowns] == [0, 1, 2, 3, 4]
    assert [td["control"]["zeta0"] for _, td in touchdowns] == [0.9, 0.87, 0.9, 0.87, 0.9]
    assert [td["rise"] for _, td in touchdowns[1:]] == pytest.approx(results["rises"])
    assert "rise" not in touchdowns[0][1]
    assert [td["state"] for _, td in touchdowns] == results["states"]
    predictions = on("/model/prediction")
    assert [time for time, _ in predictions] == [time for time, _ in touchdowns], "beside the measured touchdowns"
    assert [p["state"] for _, p in predictions] == results["prediction"]["states"]
    assert [p["measured_state"] for _, p in predictions] == [td["state"] for _, td in touchdowns]
    # Stored before runs stamped the tracker's time: each at its own Unix time (to its float64's 0.2 us).
    unix = [round(c["time"] * 1e9) for c in results["commands"]]
    assert [time for time, _ in on("/commands")] == pytest.approx(unix, abs=1000)
    assert [command for _, command in on("/commands")] == [c | {"state": []} for c in results["commands"]]
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
    simulated = make_run()  # stored without its path (a simulated run with one: test_mcap_sim.py)
    with pytest.raises(errors.Conflict, match="sim run stored without its path: nothing to record"):
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


def test_a_lagging_robot_s_records_land_among_its_frames_on_the_tracker_s_clock(session):
    """Issue 40: frames arriving at 0.37x real time, each record placed at its Unix time, put a
    command sent at a touchdown seconds after it. Now each lands at the newest frame it followed."""
    run = run_store.get_run(session, store_lagging_run(session))
    _summary, metadata, messages, every = read(exported(session, run.id)[0])
    assert [time for _topic, time in every] == sorted(time for _topic, time in every), "in log-time order"

    def on(topic: str) -> list[tuple[int, dict]]:
        return [(time, message) for name, _schema, time, message in messages if name == topic]

    start = utc_ns(run.created_at)
    frame_at = {pose["tracker_time"]: time for time, pose in on("/tracker/pose")}
    assert min(frame_at.values()) == start
    assert [time - start for time in frame_at.values()] == [round((t - TRACKER_EPOCH) * 1e9) for t in frame_at]

    stamped = [(time, record) for topic in ("/commands", "/telemetry") for time, record in on(topic)
               if "tracker_time" in record]  # fmt: skip
    assert len(stamped) > 150
    offsets = [abs(time - frame_at[record["tracker_time"]]) for time, record in stamped]
    assert max(offsets) == 0, "at the frame it followed, to the nanosecond"
    unix_offsets = [abs(round(record["time"] * 1e9) - frame_at[record["tracker_time"]]) for _, record in stamped]
    assert max(unix_offsets) > 5e9, "where its Unix time would have put it: seconds away"

    touchdowns = [time for time, _ in on("/touchdowns")]
    law = [(time, command) for time, command in on("/commands") if command["why"].startswith("pid after")]
    assert len(law) == len(touchdowns) == 5
    for (time, command), touchdown, following in zip(law, touchdowns, [*touchdowns[1:], max(frame_at.values())],
                                                     strict=True):  # fmt: skip
        assert touchdown < time < following, command["why"]
        late = (time - touchdown) / 1e9
        assert late == pytest.approx(DETECTED_AFTER, abs=FRAME_PERIOD), f"{command['why']}: {late} s after it"
    starts = [time for time, command in on("/commands") if command["why"] == "start"]
    assert len(starts) == 2 and max(starts) < start, "sent before the first frame: before it"

    link = {change["to"]: time for time, change in on("/robot/link")}
    # Unix time only: carried between the telemetry around it, stamped a frame late at most.
    bound_ns = (LAG_SPEED * TELEMETRY_EVERY + FRAME_PERIOD) * 1e9
    frame_100 = sorted(frame_at.values())[100]
    assert abs(link["running"] - frame_100) <= bound_ns, (link["running"] - frame_100) / 1e9
    assert link["armed"] < start < link["running"] < max(frame_at.values()) < link["disarmed"]
    assert metadata[METADATA_NAME]["time_convention"].startswith("log time = publish time = UTC ns on the tracker's")


def test_a_replay_of_a_lagging_run_keeps_its_source_s_clock(session):
    source = store_lagging_run(session)
    replay = replay_run(session, source)
    _s, _m, replayed, _e = read(exported(session, replay.id)[0])
    _s, _m, recorded, _e = read(exported(session, source)[0])
    for topic in ("/commands", "/telemetry", "/robot/link", "/tracker/pose"):
        assert [(t, m) for name, _, t, m in replayed if name == topic] == [
            (t, m) for name, _, t, m in recorded if name == topic
        ], topic
    assert np.diff([t for name, _, t, _ in replayed if name == "/touchdowns"]).min() > 0
