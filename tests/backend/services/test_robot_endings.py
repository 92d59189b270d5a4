"""How live runs end, against the virtual robot: a closed loop never runs blind, an open loop goes
on through a tracker gap and records it, a fall is stored as one (and calibration reads it).

The tracker reaches the service through a relay the test silences (tests/tracker_relay.py), as a
camera, its software or a switch stopping would. Asserted: what is safe (the run ended, not done,
the robot disarmed, the reason named and stored), never how fast on this machine.
"""

import socket
import time

import pytest

from backend.repositories import runs as run_store
from backend.robot.messages import RobotState
from backend.robot.virtual import VirtualRobot
from backend.schemas import ClosedLoopIn, LegIn, RobotConnect, RobotRunCreate
from backend.services.calibrations import run_fell
from sim_core.model.noise import NO_NOISE
from tests.helpers import free_port
from tests.robot_rig import wait_for
from tests.tracker_relay import TrackerRelay

LEGS = [LegIn(psi0_deg=35.0, zeta0=0.9)] * 2
RUN_WAIT_S = 60.0  # [s] "ended instead of running on": generous, not a timing claim


@pytest.fixture
def relayed(service):
    """The service connected to a virtual robot (real time) whose tracker stream passes a relay."""
    tracker_port = free_port(socket.SOCK_DGRAM)
    relay = TrackerRelay(("127.0.0.1", tracker_port)).start()
    robot = VirtualRobot(tracker_to=("127.0.0.1", relay.port), noise=NO_NOISE, speed=1.0, seed=5).start()
    status = service.connect(RobotConnect(url=robot.url, tracker_port=tracker_port))
    assert status["state"] == "disarmed", status
    yield service, robot, relay
    service.disconnect()
    robot.stop()
    relay.stop()


def _touchdowns(service) -> int:
    return len(service.run_snapshot().touchdowns)


def _stored(session, run) -> dict:
    session.expire_all()
    return run_store.get_run(session, run.run_id)


@pytest.mark.slow
@pytest.mark.realtime  # a closed loop answers each touchdown within a stance, and the bound is 60-250 ms of silence
@pytest.mark.parametrize("timeout_ms", [60.0, 100.0, 250.0])
def test_a_closed_loop_whose_tracker_goes_silent_ends_at_once_disarmed(relayed, session, timeout_ms):
    service, robot, relay = relayed
    loop = ClosedLoopIn(target_m=0.4, controller="lqr")
    service.start_run(RobotRunCreate(controls=LEGS, jumps=300, closed_loop=loop, tracker_timeout_ms=timeout_ms))
    wait_for(lambda: _touchdowns(service) >= 3, "three touchdowns", RUN_WAIT_S)
    relay.silence()
    run = service.wait_run(RUN_WAIT_S)
    assert not run.active, "the run ended"
    assert run.end_reason.startswith("tracker silent: no frame for "), run.end_reason
    assert f"(bound {timeout_ms:.0f} ms)" in run.end_reason
    assert run.disarm == "disarmed" and robot.firmware.state == RobotState.DISARMED
    stored = _stored(session, run)
    assert stored.status == "failed" and stored.results["end_reason"] == run.end_reason
    gaps = stored.results["tracker_gaps"]
    assert len(gaps) == 1 and gaps[0]["kind"] == "silent" and gaps[0]["ms"] > timeout_ms
    assert stored.results["tracker_timeout_ms"] == timeout_ms
    touchdowns = len(stored.results["touchdowns"])
    assert touchdowns < 300 and service.status()["run"]["tracker_gaps"] == 1


@pytest.mark.slow
def test_an_open_loop_goes_on_through_a_tracker_gap_and_records_it(relayed, session):
    service, _robot, relay = relayed
    service.start_run(RobotRunCreate(controls=LEGS, jumps=8, tracker_timeout_ms=100.0))
    wait_for(lambda: _touchdowns(service) >= 2, "two touchdowns", RUN_WAIT_S)
    relay.silence()
    wait_for(lambda: relay.forwarded and service.run_snapshot().active, "still running")
    gap_start = relay.forwarded
    time.sleep(0.4)
    relay.resume()
    run = service.wait_run(RUN_WAIT_S)
    assert run.end_reason == "jumps done", run.end_reason
    stored = _stored(session, run)
    assert stored.status == "done"
    gaps = stored.results["tracker_gaps"]
    # The relay's silence among them: a loaded machine may read the stream late and record more gaps.
    assert any(gap["kind"] == "silent" and gap["ms"] >= 300 for gap in gaps), gaps
    assert relay.forwarded > gap_start


def test_a_fall_is_the_runs_end_reason_and_its_record(connected, virtual, session):
    robot, _ = virtual
    service = connected
    service.start_run(RobotRunCreate(controls=LEGS, jumps=1000))
    wait_for(lambda: _touchdowns(service) >= 2, "two touchdowns", RUN_WAIT_S)
    robot._fell()  # the body hit the floor: the firmware disarms and raises FELL
    run = service.wait_run(RUN_WAIT_S)
    assert run.end_reason.startswith("fell: the robot reported a fall (FELL) after touchdown"), run.end_reason
    assert "fell" in run.robot_faults and run.disarm == "disarmed"
    stored = _stored(session, run)
    assert stored.status == "failed" and stored.results["fell"] is True and "fell" in stored.results["robot_faults"]
    assert any(entry["faults"] & 16 for entry in stored.results["telemetry"]), "the FELL telemetry is stored"
    assert run_fell(stored)


@pytest.mark.slow
@pytest.mark.realtime  # a closed loop answers each touchdown within a stance; a late frame would end it as silent
def test_a_closed_loop_whose_tracker_loses_the_body_ends_naming_it(service, session):
    """NatNet goes on streaming, but the robot's rigid body comes with its tracking-valid bit off."""
    from dataclasses import replace

    from backend.robot.natnet import parse_version
    from backend.robot.natnet_frame import decode_frame, encode_frame

    version = parse_version("3.1")

    def untracked(data: bytes) -> bytes:
        frame = decode_frame(data, version)
        body = replace(frame.rigid_body(1), tracked=False)
        return encode_frame(frame.number, frame.timestamp, body, version)

    tracker_port = free_port(socket.SOCK_DGRAM)
    relay = TrackerRelay(("127.0.0.1", tracker_port)).start()
    robot = VirtualRobot(tracker_to=("127.0.0.1", relay.port), noise=NO_NOISE, speed=1.0, seed=5,
                         tracker_protocol="natnet", natnet_version="3.1").start()  # fmt: skip
    try:
        body = RobotConnect(url=robot.url, tracker_port=tracker_port, tracker_protocol="natnet",
                            natnet_multicast_group=None, natnet_version="3.1")  # fmt: skip
        service.connect(body)
        loop = ClosedLoopIn(target_m=0.4, controller="pid")
        service.start_run(RobotRunCreate(controls=LEGS, jumps=300, closed_loop=loop))
        wait_for(lambda: _touchdowns(service) >= 2, "two touchdowns", RUN_WAIT_S)
        relay.rewrite = untracked
        run = service.wait_run(RUN_WAIT_S)
        assert not run.active and run.end_reason.startswith("tracker lost the body: frames arrive without it")
        assert run.disarm == "disarmed" and robot.firmware.state == RobotState.DISARMED
        stored = _stored(session, run)
        assert stored.status == "failed" and stored.results["tracker_gaps"][0]["kind"] == "body lost"
    finally:
        service.disconnect()
        robot.stop()
        relay.stop()


@pytest.mark.parametrize("brown_out", [False, True])
def test_a_robot_that_restarts_mid_run_is_named(connected, virtual, session, brown_out):
    robot, _ = virtual
    service = connected
    service.start_run(RobotRunCreate(controls=LEGS, jumps=1000))
    wait_for(lambda: _touchdowns(service) >= 2, "two touchdowns", RUN_WAIT_S)
    robot.reboot(brown_out=brown_out)
    run = service.wait_run(RUN_WAIT_S)
    assert run.end_reason.startswith("robot restarted: "), run.end_reason
    assert ("brown-out" in run.end_reason) is brown_out and "robot restarted (" not in run.end_reason
    assert run.disarm == "disarmed" and "booted" in run.robot_faults
    stored = _stored(session, run)
    assert stored.status == "failed" and stored.results["fell"] is False


def test_one_late_acknowledgement_is_resent_not_the_end_of_the_run(connected, virtual, session, monkeypatch):
    """The robot's answer to one SET_LEG is lost on the air: the link sends the same command again
    (same seq, applied once) and the run goes on to its jumps (it ended the run before)."""
    from backend.robot.messages import SetLeg, decode

    robot, _ = virtual
    service = connected
    receive, lost = robot._receive, []

    def lose_one_answer(payload: bytes) -> list:
        replies = receive(payload)
        if isinstance(decode(payload), SetLeg) and not lost:
            lost.append(decode(payload).seq)
            return []
        return replies

    monkeypatch.setattr(robot, "_receive", lose_one_answer)
    service.start_run(RobotRunCreate(controls=LEGS, jumps=4))
    run = service.wait_run(RUN_WAIT_S)
    assert run.end_reason == "jumps done", run.end_reason
    counters = service.status()["counters"]
    assert lost and counters["command_resends"] >= 1
    stored = _stored(session, run)
    assert stored.status == "done" and len(stored.results["touchdowns"]) == 4
