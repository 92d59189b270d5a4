"""The e-stop press through the robot service: it latches with no robot connected, and an answer
that says latched is on disk (the robot's ESTOP first, then the file, then the answer)."""

import json
import time

import pytest

from backend.robot.link import EstopLatched
from backend.robot.messages import RobotState
from backend.schemas import LegIn, RobotConnect, RobotRunCreate
from backend.services.robot import RobotService, RobotUnavailable
from backend.services.robot_estop import NOT_CONNECTED
from tests.robot_rig import wait_for

LEGS = [LegIn(psi0_deg=30.0, zeta0=0.87), LegIn(psi0_deg=30.0, zeta0=0.9)]
SLOW_DISK_S = 0.1  # [s] each latch write takes this long here


@pytest.fixture
def latch_path(tmp_path):
    return tmp_path / "estop-latch.json"


def _service(sessions, latch_path) -> RobotService:
    return RobotService(sessions, latch_path=latch_path)


def test_a_press_with_no_robot_connected_latches_and_the_next_connect_stops_the_robot_first(
    sessions, latch_path, virtual
):
    robot, tracker_port = virtual
    service = _service(sessions, latch_path)
    try:
        answer = service.estop()
        assert answer["acknowledged"] is False and answer["reason"] == NOT_CONNECTED
        assert answer["estop"]["latched"] is True and answer["estop"]["durable"] is True
        assert answer["estop"]["reason"].startswith("emergency stop, no robot connected: the next connect sends it")
        assert json.loads(latch_path.read_text())["held"] is True, "on disk when it answered"
    finally:
        service.close()

    service = _service(sessions, latch_path)  # a restart of the service finds it held
    try:
        assert robot.firmware.state == RobotState.DISARMED
        status = service.connect(RobotConnect(url=robot.url, tracker_port=tracker_port))
        assert status["estop"]["latched"] is True
        # Connected means first telemetry heard; the latched ESTOP goes in place of heartbeats and
        # reaches the robot on its own thread's time (on a loaded machine, after connect returns).
        wait_for(lambda: robot.firmware.state == RobotState.ESTOPPED, "the robot e-stopped by the connect's ESTOP")
        with pytest.raises(EstopLatched):
            service.arm()
        with pytest.raises(RobotUnavailable, match="latch holds"):
            service.start_run(RobotRunCreate(controls=LEGS, jumps=3))
        assert robot.firmware.state == RobotState.ESTOPPED
        service.reset()
        assert service.status()["estop"]["latched"] is False and robot.firmware.state == RobotState.DISARMED
        service.arm()
        assert robot.firmware.state == RobotState.ARMED
    finally:
        service.close()


@pytest.mark.parametrize("connected_robot", [False, True])
def test_the_answer_waits_for_the_latch_file_never_the_robot_for_the_disk(
    sessions, latch_path, virtual, monkeypatch, connected_robot, patient_estop
):
    """A slow disk: the robot is e-stopped before the file is written, and the answer comes after it
    (a kill -9 right after the answer found the latch released 4 times in 7)."""
    robot, tracker_port = virtual
    service = _service(sessions, latch_path)
    write = service.latch._write
    seen_at_write = []

    def slow_write(*args):
        time.sleep(SLOW_DISK_S)
        seen_at_write.append(robot.firmware.state)  # before the file is written
        write(*args)

    monkeypatch.setattr(service.latch, "_write", slow_write)
    try:
        if connected_robot:
            service.connect(RobotConnect(url=robot.url, tracker_port=tracker_port))
        for _ in range(3):
            answer = service.estop()
            assert json.loads(latch_path.read_text())["held"] is True, "the file says held when it answers"
            assert answer["estop"]["latched"] is True and answer["estop"]["durable"] is True
        if connected_robot:
            assert answer["acknowledged"] is True
            assert seen_at_write[0] == RobotState.ESTOPPED, "the robot was e-stopped before the file was written"
    finally:
        service.close()
