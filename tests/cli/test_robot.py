"""``parkour robot-sim`` (cli/robot.py): the virtual robot listening until Ctrl-C, its true physics
and imperfections taken from the options, and a bad tracker address named.

The command's wait is cut short here: its ``time.sleep`` (the module's own) stands for the person
who presses Ctrl-C, after the test has talked to the robot.
"""

from __future__ import annotations

import socket
from types import SimpleNamespace

import pytest

import cli.robot
from sim_core.model.controls import LegOffsets
from sim_core.model.noise import NO_NOISE
from tests.cli.helpers import invoke
from tests.helpers import free_port


class CtrlC:
    """The command's ``time``: its first sleep runs ``meanwhile()`` and then presses Ctrl-C."""

    def __init__(self, meanwhile=lambda: None):
        self.meanwhile = meanwhile

    def sleep(self, _seconds: float) -> None:
        self.meanwhile()
        raise KeyboardInterrupt


def test_the_virtual_robot_listens_until_ctrl_c_and_then_lets_its_port_go(monkeypatch):
    port, tracker = free_port(), free_port(socket.SOCK_DGRAM)
    received = []

    def talk_to_it():
        with socket.create_connection(("127.0.0.1", port), timeout=5) as radio:
            received.append(radio.recv(64))  # the robot's telemetry, sent every tick

    monkeypatch.setattr(cli.robot, "time", CtrlC(talk_to_it))
    result = invoke("robot-sim", "--port", str(port), "--tracker", f"127.0.0.1:{tracker}", "--noise", "off")
    assert result.exit_code == 0, result.output
    assert received and received[0], "a connection to the port reaches the robot, which speaks"
    assert f"virtual robot listening: socket://127.0.0.1:{port}" in result.stderr
    assert f"tracker (pkt1) to udp://127.0.0.1:{tracker}" in result.stderr
    with pytest.raises(ConnectionRefusedError):
        socket.create_connection(("127.0.0.1", port), timeout=5).close()


def test_the_options_are_the_robots_truth_and_imperfections(monkeypatch):
    made = {}

    class Robot:
        url = "socket://127.0.0.1:9750"

        def __init__(self, host, port, **options):
            made.update(options, host=host, port=port)

        def start(self):
            return self

        def stop(self):
            made["stopped"] = True

    monkeypatch.setattr("backend.robot.virtual.VirtualRobot", Robot)
    monkeypatch.setattr(cli.robot, "time", CtrlC())
    result = invoke("robot-sim", "--host", "0.0.0.0", "--port", "9760", "--tracker", "10.0.0.2:9999",
                    "--seed", "7", "--noise", "off", "--alpha", "70", "--psi0-offset-deg", "0.5", "-0.5",
                    "--zeta0-offset", "0.01", "0", "--tracker-protocol", "natnet", "--natnet-version", "4.1",
                    "--natnet-rigid-body-id", "3")  # fmt: skip
    assert result.exit_code == 0, result.output
    assert (made["host"], made["port"], made["tracker_to"], made["seed"]) == ("0.0.0.0", 9760, ("10.0.0.2", 9999), 7)
    assert made["robot"].to_model().alpha == pytest.approx(70.0), "its true physics: the model options"
    assert made["leg_offsets"] == LegOffsets(psi0_offset_deg=(0.5, -0.5), zeta0_offset=(0.01, 0.0))
    assert (made["noise"], made["tracker_noise"], made["drop_rate"]) == (NO_NOISE, 0.0, 0.0), "--noise off: none"
    assert (made["tracker_protocol"], made["natnet_version"], made["natnet_rigid_body_id"]) == ("natnet", "4.1", 3)
    assert made["stopped"], "stopped on Ctrl-C"


def test_with_noise_on_the_robot_keeps_its_default_imperfections(monkeypatch):
    made = {}
    robot = SimpleNamespace(url="socket://127.0.0.1:1", start=lambda: robot, stop=lambda: None)
    monkeypatch.setattr("backend.robot.virtual.VirtualRobot", lambda *args, **options: made.update(options) or robot)
    monkeypatch.setattr(cli.robot, "time", CtrlC())
    assert invoke("robot-sim").exit_code == 0
    assert not {"noise", "tracker_noise", "drop_rate"} & set(made), "the robot's own defaults"


@pytest.mark.parametrize("tracker", ["9751", "localhost:", ":9751", "localhost:port"])
def test_a_tracker_address_that_is_not_host_port_is_named(monkeypatch, tracker):
    monkeypatch.setattr("backend.robot.virtual.VirtualRobot", lambda *args, **options: pytest.fail("started"))
    result = invoke("robot-sim", "--tracker", tracker)
    assert result.exit_code == 2
    assert result.stderr.strip() == f"error: tracker: must be HOST:PORT, got {tracker!r}"
