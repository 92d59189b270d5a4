"""The port kept by a radio process: LinkPort's interface (frames whole, a closed port says so, a bad
URL names itself), the cadence it keeps with what it is handed, and a process that never outlives
its service — closed, or killed outright — nor a Ctrl-C before the service's own shutdown."""

import os
import re
import signal
import socket
import subprocess
import sys
import time

import pytest

from backend.robot import radio_process as radio
from backend.robot.link import LinkState, RobotLink
from backend.robot.link_types import LinkError
from backend.robot.messages import Command, Kind, decode
from backend.robot.process_port import ProcessPort
from backend.robot.virtual import VirtualRobot
from backend.robot.xbee import ROBOT_ADDRESS, FrameParser, parse_tx_request
from tests.helpers import ROOT

GONE_WITHIN = 20.0  # [s] generous: a loaded machine; a process that outlives its service never goes


def echoed(port: ProcessPort, count: int, timeout: float = 10.0) -> list:
    """The first ``count`` messages a loop:// radio process echoed back, in order."""
    parser, messages = FrameParser(), []
    deadline = time.monotonic() + timeout
    while len(messages) < count and time.monotonic() < deadline:
        messages += [decode(parse_tx_request(frame)[2]) for frame in parser.feed(port.read())]
    return messages


def gone(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return True
    # A zombie is gone too (its parent, the test runner here, has not reaped it yet).
    with open(f"/proc/{pid}/stat") as stat:
        return stat.read().split(")")[-1].split()[0] == "Z"


def wait_gone(pid: int) -> None:
    deadline = time.monotonic() + GONE_WITHIN
    while not gone(pid):
        assert time.monotonic() < deadline, f"the radio process {pid} outlived its service"
        time.sleep(0.05)


@pytest.fixture
def loop_port():
    port = ProcessPort("loop://", 57_600, ROBOT_ADDRESS)
    port.open()
    yield port
    port.close()


def test_messages_go_out_as_frames_in_order_and_their_count_comes_back(loop_port):
    for seq in range(1, 4):
        loop_port.write(Command(seq, Kind.ARM))
    assert [message.seq for message in echoed(loop_port, 3)] == [1, 2, 3] and loop_port.frames_out == 3


def test_frames_queued_for_the_cadence_go_out_in_order_and_a_drop_takes_the_rest_back(loop_port):
    for seq in range(1, 4):
        loop_port.queue(Command(seq, Kind.HEARTBEAT))
    assert [message.seq for message in echoed(loop_port, 3)] == [1, 2, 3], "written on the radio process' own clock"
    for seq in range(4, 9):
        loop_port.queue(Command(seq, Kind.HEARTBEAT))
    loop_port.drop_queued()
    assert loop_port.queued == 0
    loop_port.write(Command(99, Kind.ESTOP))
    # What went before the drop returned (a few, on a loaded machine) and the ESTOP; then nothing more
    # for five periods of the cadence.
    after = [message.seq for message in echoed(loop_port, 100, timeout=0.5)]
    assert 99 in after and after[-1] == 99, f"nothing queued went after the drop: {after}"


def test_a_closed_port_refuses_to_write_and_reads_nothing():
    port = ProcessPort("loop://", 57_600, ROBOT_ADDRESS)
    with pytest.raises(LinkError, match="the link is down"):
        port.write(Command(1, Kind.HEARTBEAT))
    assert port.read() == b"" and not port.is_open and port.frames_out == 0 and port.pid is None


@pytest.mark.parametrize("what", ["refused", "a regular file"])
def test_a_port_that_cannot_be_opened_is_named_and_leaves_no_process(what, tmp_path):
    with socket.socket() as bound:  # bound here and never listening: connections to it are refused
        bound.bind(("127.0.0.1", 0))
        if what == "refused":
            url = f"socket://127.0.0.1:{bound.getsockname()[1]}"
            reason = rf"cannot open {re.escape(url)}: .*refused"
        else:
            url, reason = str(tmp_path / "hostname"), "not a character device"
            (tmp_path / "hostname").write_text("lab\n")
        port = ProcessPort(url, 57_600, ROBOT_ADDRESS)
        with pytest.raises(LinkError, match=reason):
            port.open()
    assert not port.is_open and port.pid is None


def test_closing_ends_the_radio_process_and_a_ctrl_c_does_not(loop_port):
    pid = loop_port.pid
    os.kill(pid, signal.SIGINT)  # the service's process group gets a Ctrl-C: the service disarms first
    loop_port.write(Command(1, Kind.DISARM))
    assert [message.kind for message in echoed(loop_port, 1)] == [Kind.DISARM], "it still writes"
    loop_port.close()
    wait_gone(pid)


SERVICE = """
import sys, time
from backend.robot.link import RobotLink
link = RobotLink(sys.argv[1], radio_process=True)
link.connect()
link.arm()
print(link.port.pid, flush=True)
time.sleep(600)
"""


def test_a_service_killed_outright_takes_its_radio_process_with_it_and_the_robot_disarms():
    robot = VirtualRobot().start()
    service = subprocess.Popen([sys.executable, "-c", SERVICE, robot.url], stdout=subprocess.PIPE, cwd=ROOT, text=True)
    try:
        pid = int(service.stdout.readline())
        assert robot.firmware.state.name == "ARMED"
        service.kill()
        service.wait()
        wait_gone(pid)
        deadline = time.monotonic() + GONE_WITHIN
        while robot.firmware.state.name != "DISARMED":
            assert time.monotonic() < deadline, "the robot's watchdog disarmed it"
            time.sleep(0.05)
    finally:
        service.kill()
        robot.stop()


def test_the_link_through_a_radio_process_arms_commands_and_stops_the_robot(patient_estop):
    robot = VirtualRobot().start()
    link = RobotLink(robot.url, radio_process=True)
    try:
        link.connect()
        pid = link.port.pid
        link.arm()
        assert link.estop().acknowledged and link.state == LinkState.ESTOPPED
        link.reset()
        assert link.state == LinkState.DISARMED and robot.firmware.state.name == "DISARMED"
        assert link.port.queued >= 1, "heartbeats queued at the reset, not at the heartbeat thread's next turn"
        counters = link.counters()
        assert counters["frames_out"] >= 3 and counters["write_timeouts"] == 0
    finally:
        link.close()
        robot.stop()
    wait_gone(pid)


def test_an_answer_given_up_on_is_not_taken_for_the_next_requests():
    """A radio process kept from running past a request's bound answers it late: the port passes that
    answer over and waits for its own (each answer names its request)."""
    port = ProcessPort("loop://", 57_600, ROBOT_ADDRESS)
    port._control, child = socket.socketpair(socket.AF_UNIX, socket.SOCK_SEQPACKET)
    try:
        with pytest.raises(LinkError, match="did not answer"):
            port.write(Command(1, Kind.ARM), deadline=time.monotonic())  # nobody answers in time
        child.recv(radio.CHUNK)
        late = radio.ANSWER.pack(1, radio.TIMED_OUT, 0, 1, 0)  # the first request's, at last
        child.send(late)
        child.send(radio.ANSWER.pack(2, radio.OK, 1, 1, 3))  # the second's, sent ahead of time
        port.queue(Command(2, Kind.HEARTBEAT))
        assert (port.frames_out, port.queued) == (1, 3), "the second request's answer, not the first's"
        head = child.recv(radio.CHUNK)
        assert head[:1] == radio.QUEUE and radio.HEAD.unpack_from(head, 1)[0] == 2
    finally:
        port._control.close()
        child.close()
