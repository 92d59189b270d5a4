"""The robot service called directly, against the virtual robot: connect, a short live run, replay.

Through the API, tests/backend/api/routes/test_robot.py covers e-stop, a lost link and reconnects.
"""

import asyncio
import io
import logging
import threading
import time

import pytest
from google.protobuf.json_format import MessageToDict
from mcap.reader import make_reader
from mcap_protobuf.decoder import DecoderFactory

from backend import errors
from backend.repositories import runs as run_store
from backend.robot.link import LinkError
from backend.robot.live_run import LiveRun, RunSnapshot
from backend.robot.messages import Fault, RobotState
from backend.robot.virtual import VirtualRobot
from backend.schemas import ClosedLoopIn, LegIn, RobotConnect, RobotRunCreate
from backend.services.mcap_export import export_run
from backend.services.mcap_schemas import TOPICS, message_class
from backend.services.robot import ANSWER_WAIT, RobotUnavailable
from backend.services.robot_records import replay_run, touchdown_results
from backend.store.trajectory_blob import unpack_trajectory
from sim_core import ParameterError, get_preset
from tests.helpers import answer_within
from tests.robot_rig import FOREIGN, LinkCalls, PtyRobot, Radio, received_frame, telemetry

LEGS = [LegIn(psi0_deg=30.0, zeta0=0.87), LegIn(psi0_deg=30.0, zeta0=0.9)]  # [left, right]
JUMPS = 4
RUN_WAIT_S = 30.0  # [s] an upper bound for a 4-jump run at 4x speed, not a timing assertion
ANSWER_BOUND_S = 2.0  # [s] "answers instead of hanging": generous, not a latency claim
FRAME_PERIOD = 0.01  # [s] of tracker time: the virtual robot's camera runs at 100 Hz
FLAP_S = 4.0  # [s] the radio flaps in the service's test (tests/backend/robot/test_supervisor.py flaps longer)
FLAP_ANSWER_S = 20.0  # [s] a connect, a close or the threads' end, instead of a hang: generous


def _live_run(service, **fields) -> dict:
    """Start a live run, wait for its end, and return the service's status then."""
    service.start_run(RobotRunCreate(controls=LEGS, jumps=JUMPS, **fields))
    assert not service.wait_run(RUN_WAIT_S).active, "the live run did not end"
    return service.status()


def test_without_a_robot_nothing_moves(service):
    status = service.status()
    assert (status["state"], status["url"], status["tracker"], status["run"]) == ("disconnected", None, None, None)
    assert status["transitions"] == [] and service.live()["recent_touchdowns"] == []
    for command in (service.arm, service.disarm, service.reset):
        with pytest.raises(RobotUnavailable, match="not connected"):
            command()
    stopped = service.estop()  # always answers: stopping is always allowed, and latches
    assert stopped["acknowledged"] is False and stopped["reason"].startswith("the robot is not connected")
    assert stopped["estop"]["latched"] is True
    with pytest.raises(RobotUnavailable):
        service.start_run(RobotRunCreate(controls=LEGS))
    assert service.stop_run()["run"] is None, "nothing to stop is no error: stopping is always possible"


def test_a_live_run_is_stored_with_the_models_prediction(connected, session):
    status = _live_run(connected, tags=["live"])
    assert status["run"]["end_reason"] == "jumps done" and not status["run"]["active"]
    assert status["state"] == "disarmed", "the robot is disarmed when the run ends"
    stored = run_store.get_run(session, status["run"]["stored_run_id"])
    assert (stored.kind, stored.status, stored.tags, stored.jumps) == ("robot", "done", ["live"], JUMPS)
    assert stored.controls == [[30.0, 0.87], [30.0, 0.9]] and stored.jumps_completed == JUMPS - 1
    results = stored.results
    assert len(results["touchdowns"]) == JUMPS and len(results["rises"]) == JUMPS - 1
    assert results["prediction"]["failure"] is None and len(results["prediction"]["states"]) == JUMPS
    assert results["states"][0] == stored.start_state
    assert [command["why"] for command in results["commands"]] == ["start", "start"]
    frames = unpack_trajectory(stored.trajectory)
    assert set(frames) == {"time", "x", "y", "pitch"} and frames["time"].size == results["tracker"]["frames"] > 0


# Real time: how many poses arrive between two scans is the tracker's rate times how long the loop
# waited for the interpreter; beside other work (two busy loops: 352 of 2,618) that passes the bound.
@pytest.mark.realtime
def test_a_long_live_run_scans_only_the_poses_of_its_last_flight(connected, session, monkeypatch):
    """Each new tracker pose costs the control loop the same at the 40th jump as at the first: it
    scans only the poses since its last scan (it rescanned the whole run at every pose, which at a
    few thousand poses held the interpreter long enough to starve the link's heartbeats)."""
    from backend.robot import live_run

    windows = []

    def scan(time, *args, start, **kwargs):
        windows.append((time.size, time.size - start))
        return live_run_scan(time, *args, start=start, **kwargs)

    live_run_scan = live_run.scan_touchdowns
    monkeypatch.setattr(live_run, "scan_touchdowns", scan)
    connected.start_run(RobotRunCreate(controls=LEGS, jumps=40))
    status = connected.wait_run(RUN_WAIT_S * 4)
    assert status.end_reason == "jumps done", status.end_reason
    frames = run_store.get_run(session, status.run_id).results["tracker"]["frames"]
    longest = max(new for _, new in windows)
    assert frames > 1000 and longest < frames / 10, f"a scan went over {longest} of {frames} poses"
    assert max(size for size, _ in windows) < frames / 10, "a scan looks back over one flight at most"
    print(f"{frames} poses in {len(windows)} scans of at most {longest} poses")


@pytest.mark.slow
@pytest.mark.robot_speed(0.37)
def test_a_lagging_robot_s_records_are_stamped_with_the_tracker_s_time(connected, session):
    """Issue 40: the virtual robot climbing at 0.37x real time, closed loop. Each command and
    telemetry carries the tracker time of the newest frame the service had, and its recording places
    it there: each of the law's commands at the touchdown it answers, before the next."""
    request = RobotRunCreate(controls=LEGS, jumps=JUMPS, closed_loop=ClosedLoopIn(target_m=0.4))
    connected.start_run(request)
    status = connected.wait_run(RUN_WAIT_S)
    assert not status.active and status.end_reason == "jumps done", status.end_reason
    results = run_store.get_run(session, status.run_id).results
    frames = unpack_trajectory(run_store.get_run(session, status.run_id).trajectory)["time"]
    for topic, records in (("/commands", results["commands"]), ("/telemetry", results["telemetry"])):
        fields = message_class(TOPICS[topic]).DESCRIPTOR.fields_by_name
        assert [set(record) - set(fields) for record in records] == [set()] * len(records), "nothing left out"
        stamps = [record["tracker_time"] for record in records if record["tracker_time"] is not None]
        assert stamps and set(stamps) <= set(frames.tolist()), f"{topic}: a frame's time, the run's own"
        assert stamps == sorted(stamps)

    stream = io.BytesIO()
    export_run(session, status.run_id, stream)
    reader = make_reader(io.BytesIO(stream.getvalue()), decoder_factories=[DecoderFactory()])
    placed = {topic: [] for topic in TOPICS}
    for _schema, channel, message, decoded in reader.iter_decoded_messages(topics=list(TOPICS)):
        placed[channel.topic].append(
            (
                message.log_time,
                MessageToDict(decoded, preserving_proto_field_name=True, always_print_fields_with_no_presence=True),
            )
        )
    frame_at = {pose["tracker_time"]: time for time, pose in placed["/tracker/pose"]}
    stamped = [(time, record) for topic in ("/commands", "/telemetry") for time, record in placed[topic]
               if "tracker_time" in record]  # fmt: skip
    assert all(time == frame_at[record["tracker_time"]] for time, record in stamped)
    touchdowns = [time for time, _ in placed["/touchdowns"]]
    law = [time for time, command in placed["/commands"] if command["why"].startswith("pid after touchdown")]
    assert len(law) == len(touchdowns) == JUMPS
    # The loop may answer from the frame just before the touchdown time its fit puts between frames.
    early_ns = 2 * FRAME_PERIOD * 1e9
    assert all(touchdown - early_ns < time for touchdown, time in zip(touchdowns, law, strict=True))
    assert all(time < touchdown for time, touchdown in zip(law, touchdowns[1:], strict=False)), "before the next"


def test_a_recorded_run_replays_to_the_same_touchdowns(connected, session, make_run):
    live_id = _live_run(connected)["run"]["stored_run_id"]
    replay = replay_run(session, live_id)
    live = run_store.get_run(session, live_id)
    assert (replay.kind, replay.results["source_run_id"], replay.tags) == ("replay", live_id, ["replay"])
    assert replay.results["states"] == live.results["states"] and replay.climb == pytest.approx(live.climb)
    simulated = make_run()
    with pytest.raises(errors.Conflict, match="only robot runs"):
        replay_run(session, simulated.id)
    with pytest.raises(errors.NotFound):
        replay_run(session, 999)


def test_commands_beyond_the_servo_limits_are_refused_before_anything_moves(connected, virtual):
    robot, _ = virtual
    with pytest.raises(ParameterError) as error:
        connected.start_run(RobotRunCreate(controls=[LegIn(psi0_deg=30.0, zeta0=0.99), LEGS[1]]))
    assert error.value.field == "zeta0"
    assert connected.status()["run"] is None and robot.firmware.state.name == "DISARMED"


def test_disconnect_closes_the_link_and_the_tracker(connected):
    assert connected.status()["tracker"]["address"][1] > 0
    status = connected.disconnect()
    assert (status["state"], status["tracker"]) == ("disconnected", None)
    with pytest.raises(RobotUnavailable):
        connected.arm()


def test_touchdown_results_need_two_touchdowns_for_a_prediction():
    robot = get_preset("paper")
    assert touchdown_results([], [], robot) == {"touchdowns": [], "states": [], "rises": [], "prediction": None}


def _wait_for(predicate, what: str, timeout=RUN_WAIT_S) -> None:
    deadline = time.monotonic() + timeout
    while not predicate():
        assert time.monotonic() < deadline, f"{what} within {timeout:g} s"
        time.sleep(0.01)


def test_a_foreign_radio_cannot_end_a_live_run(connected, virtual, session):
    robot, _ = virtual
    seen = len(_running(connected, connected.start_run(RobotRunCreate(controls=LEGS, jumps=1000))).touchdowns)
    robot.inject(received_frame(telemetry(1, RobotState.DISARMED), source64=FOREIGN) * 3)
    _wait_for(lambda: connected.status()["counters"]["foreign_frames"] == 3, "three foreign frames counted")
    _wait_for(lambda: len(connected.run_snapshot().touchdowns) >= seen + 2, "two more touchdowns")
    assert connected.run_snapshot().active and connected.status()["state"] == "running"
    assert robot.firmware.state == RobotState.RUNNING
    status = connected.stop_run()
    assert status["run"]["end_reason"] == "stopped" and status["state"] == "disarmed"
    assert run_store.get_run(session, status["run"]["stored_run_id"]).status == "done"


def test_estop_ends_a_live_run_even_unacknowledged(service):
    run = LiveRun(jumps=4, max_seconds=60.0)
    service._run = run  # a run whose link is gone
    stopped = service.estop()
    assert stopped["acknowledged"] is False and run.stop_reason() == "e-stop"
    run.done.set()


def test_estop_on_a_jammed_line_answers_in_bound_and_honestly(service):
    rig = PtyRobot(RobotState.ARMED).start()
    try:
        status = service.connect(RobotConnect(url=rig.path, tracker_port=0))
        assert status["state"] == "armed"
        rig.jam()
        stopped = answer_within(ANSWER_BOUND_S, asyncio.run, service.estop_now())
        assert stopped["acknowledged"] is False and "no acknowledgement" in stopped["reason"]
        assert stopped["state"] == "armed" and stopped["counters"]["estops_unacknowledged"] == 1
        with pytest.raises(LinkError, match="reset before you arm"):
            service.arm()
    finally:
        service.disconnect()
        rig.stop()


def test_estop_now_answers_even_when_the_estop_thread_is_stuck(service, monkeypatch):
    release = threading.Event()
    calls = []

    def stuck(_by=None):
        calls.append(1)
        release.wait(5)
        return {"acknowledged": True}

    monkeypatch.setattr(service, "estop", stuck)

    async def press_twice():
        return await asyncio.gather(service.estop_now(), service.estop_now())

    answers = answer_within(ANSWER_BOUND_S, asyncio.run, press_twice())
    release.set()
    for answer in answers:
        assert answer["acknowledged"] is False and "did not finish" in answer["reason"]
        assert answer["latency_ms"] == pytest.approx(ANSWER_WAIT * 1000)
    assert len(calls) == 1, "a press during an e-stop joins it"


def test_the_services_link_has_one_owner_while_it_flaps(service, monkeypatch, caplog):
    """The service's connect, the lost link's reconnects and its close all go through the supervisor."""
    caplog.set_level(logging.DEBUG, logger="parkourlab.robot")
    thread_errors = []
    monkeypatch.setattr(threading, "excepthook", thread_errors.append)
    calls = LinkCalls(monkeypatch)
    baseline = threading.active_count()
    radio = Radio(seed=3)
    robot = VirtualRobot("127.0.0.1", radio.port).start()
    body = RobotConnect(url=radio.url, tracker_port=0)
    assert answer_within(FLAP_ANSWER_S, service.connect, body)["state"] == "disarmed"
    robot.stop()
    radio.flap(FLAP_S)
    radio.join()
    robot = VirtualRobot("127.0.0.1", radio.port).start()
    try:
        _wait_for(lambda: service.status()["state"] == "disarmed", "the link back once the robot is")
        answer_within(FLAP_ANSWER_S, service.close)
    finally:
        robot.stop()
    _wait_for(lambda: threading.active_count() <= baseline + 1, "the threads back to the baseline", FLAP_ANSWER_S)
    errors = [r for r in caplog.records if r.levelno >= logging.WARNING or r.exc_info]
    assert errors == [] and thread_errors == [], (errors, thread_errors)
    assert calls.most_connecting == 1 and calls.callers == {"robot-link-supervisor"}, calls.callers


def _running(service, _started: RunSnapshot) -> RunSnapshot:
    """The live run just started, once it has two touchdowns."""
    _wait_for(lambda: len(service.run_snapshot().touchdowns) >= 2, "two touchdowns")
    return service.run_snapshot()


def _ended(service) -> RunSnapshot:
    run = service.wait_run(RUN_WAIT_S)
    assert not run.active, "the live run did not end"
    return run


def _end_by_jumps(service, robot) -> RunSnapshot:
    service.start_run(RobotRunCreate(controls=LEGS, jumps=JUMPS))
    return _ended(service)


def _end_by_stop(service, robot) -> RunSnapshot:
    _running(service, service.start_run(RobotRunCreate(controls=LEGS, jumps=1000)))
    service.stop_run()
    return _ended(service)


def _end_by_the_time_limit(service, robot) -> RunSnapshot:
    service.start_run(RobotRunCreate(controls=LEGS, jumps=1000, max_seconds=1.0))
    run = _ended(service)
    assert run.end_reason == "time limit", run.end_reason
    return run


def _end_by_a_stale_disarmed_telemetry(service, robot) -> RunSnapshot:
    # The link believes the robot disarmed while it runs on: the ending must disarm it all the same.
    _running(service, service.start_run(RobotRunCreate(controls=LEGS, jumps=1000)))
    robot.inject(received_frame(telemetry(1, RobotState.DISARMED)))
    run = _ended(service)
    assert run.end_reason.startswith("robot disarmed")
    return run


def _end_by_shutdown(service, robot) -> RunSnapshot:
    _running(service, service.start_run(RobotRunCreate(controls=LEGS, jumps=1000)))
    answer_within(FLAP_ANSWER_S, service.close)
    return service.run_snapshot()


@pytest.mark.parametrize(
    "end", [_end_by_jumps, _end_by_stop, _end_by_the_time_limit, _end_by_a_stale_disarmed_telemetry, _end_by_shutdown]
)
def test_every_ending_disarms_the_robot(connected, virtual, session, end):
    robot, _ = virtual
    run = end(connected, robot)
    assert not run.active and run.disarm == "disarmed", (run.end_reason, run.disarm)
    assert robot.firmware.state == RobotState.DISARMED, run.end_reason
    assert not robot.firmware.faults & Fault.HEARTBEAT_LOST, "disarmed by a DISARM, not by its watchdog"
    assert run_store.get_run(session, run.run_id).results["disarm"] == "disarmed"


def test_an_estop_ending_leaves_the_robot_estopped(connected, virtual, patient_estop):
    robot, _ = virtual
    _running(connected, connected.start_run(RobotRunCreate(controls=LEGS, jumps=1000)))
    assert connected.estop()["acknowledged"] is True
    assert _ended(connected).disarm == "estopped" and robot.firmware.state == RobotState.ESTOPPED


@pytest.mark.parametrize("ending", ["disconnect", "close"])
def test_disconnecting_an_armed_robot_disarms_it(connected, virtual, ending):
    robot, _ = virtual
    connected.arm()
    assert robot.firmware.state == RobotState.ARMED
    answer_within(FLAP_ANSWER_S, getattr(connected, ending))
    assert robot.firmware.state == RobotState.DISARMED and not robot.firmware.faults & Fault.HEARTBEAT_LOST
