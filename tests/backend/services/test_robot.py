"""The robot service called directly, against the virtual robot: connect, a short live run, replay.

Through the API, tests/backend/api/test_robot_api.py covers e-stop, a lost link and reconnects.
"""

import pytest

from backend.schemas import LegIn, RobotConnect, RobotRunCreate
from backend.services import records
from backend.services.robot import RobotService, RobotUnavailable, replay_run, touchdown_results
from backend.services.simulation import unpack_trajectory
from sim_core import ParameterError, get_preset

LEGS = [LegIn(psi0_deg=30.0, zeta0=0.87), LegIn(psi0_deg=30.0, zeta0=0.9)]  # [left, right]
JUMPS = 4
RUN_WAIT_S = 30.0  # [s] an upper bound for a 4-jump run at 4x speed, not a timing assertion


@pytest.fixture
def service(sessions):
    service = RobotService(sessions)
    yield service
    service.disconnect()


@pytest.fixture
def connected(service, virtual):
    robot, tracker_port = virtual
    status = service.connect(RobotConnect(url=robot.url, tracker_port=tracker_port))
    assert status["state"] == "disarmed", status
    return service


def _live_run(service, **fields) -> dict:
    """Start a live run, wait for its end, and return the service's status then."""
    run = service.start_run(RobotRunCreate(controls=LEGS, jumps=JUMPS, **fields))
    assert run.done.wait(RUN_WAIT_S), "the live run did not end"
    return service.status()


def test_without_a_robot_nothing_moves(service):
    status = service.status()
    assert (status["state"], status["url"], status["tracker"], status["run"]) == ("disconnected", None, None, None)
    assert status["transitions"] == [] and service.live()["recent_touchdowns"] == []
    for command in (service.arm, service.disarm, service.reset, service.estop):
        with pytest.raises(RobotUnavailable, match="not connected"):
            command()
    with pytest.raises(RobotUnavailable):
        service.start_run(RobotRunCreate(controls=LEGS))
    with pytest.raises(records.NotFound):
        service.stop_run()


def test_a_live_run_is_stored_with_the_models_prediction(connected, session):
    status = _live_run(connected, tags=["live"])
    assert status["run"]["end_reason"] == "jumps done" and not status["run"]["active"]
    assert status["state"] == "disarmed", "the robot is disarmed when the run ends"
    stored = records.get_run(session, status["run"]["stored_run_id"])
    assert (stored.kind, stored.status, stored.tags, stored.jumps) == ("robot", "done", ["live"], JUMPS)
    assert stored.controls == [[30.0, 0.87], [30.0, 0.9]] and stored.jumps_completed == JUMPS - 1
    results = stored.results
    assert len(results["touchdowns"]) == JUMPS and len(results["rises"]) == JUMPS - 1
    assert results["prediction"]["failure"] is None and len(results["prediction"]["states"]) == JUMPS
    assert results["states"][0] == stored.start_state
    assert [command["why"] for command in results["commands"]] == ["start", "start"]
    frames = unpack_trajectory(stored.trajectory)
    assert set(frames) == {"time", "x", "y", "pitch"} and frames["time"].size == results["tracker"]["frames"] > 0


def test_a_recorded_run_replays_to_the_same_touchdowns(connected, session, make_run):
    live_id = _live_run(connected)["run"]["stored_run_id"]
    replay = replay_run(session, live_id)
    live = records.get_run(session, live_id)
    assert (replay.kind, replay.results["source_run_id"], replay.tags) == ("replay", live_id, ["replay"])
    assert replay.results["states"] == live.results["states"] and replay.climb == pytest.approx(live.climb)
    simulated = make_run()
    with pytest.raises(records.Conflict, match="only robot runs"):
        replay_run(session, simulated.id)
    with pytest.raises(records.NotFound):
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
