"""The robot's bodies (backend/schemas/robot.py): opening the link (a serial port or socket, the
tracker, the NatNet stream, the camera calibration, the servo limits) and a live run, each bounded."""

import pytest

from backend.robot.natnet import MULTICAST_GROUP
from backend.robot.xbee import ROBOT_ADDRESS
from backend.schemas.common import MAX_ID
from backend.schemas.robot import ClosedLoopIn, EstopLatchOut, RobotConnect, RobotEstopOut, RobotRunCreate
from tests.backend.schemas.refusals import LEG, accepted, refusal_messages, refused

CONNECT = {"url": "loop://"}
RUN = {"controls": [LEG, LEG]}


def test_a_link_opens_with_the_lab_defaults():
    link = accepted(RobotConnect, CONNECT)
    assert int(link.robot_address, 16) == ROBOT_ADDRESS and (link.baud, link.tracker_port) == (57_600, 9751)
    assert (link.tracker_protocol, link.natnet_version) == ("pkt1", "auto")
    assert link.natnet_multicast_group == MULTICAST_GROUP
    assert (link.psi0_limits_deg, link.zeta0_limits) == ([10.0, 60.0], [0.75, 0.98])


@pytest.mark.parametrize("url", ["loop://", "socket://localhost:9750", "rfc2217://10.0.0.2:4000", "COM3"])
def test_serial_urls_and_robot_sockets_are_accepted(url):
    assert accepted(RobotConnect, {"url": url}).url == url


@pytest.mark.parametrize("url", ["http://robot", "socket://a b:1", "ttyUSB0", "/nonexistent/ttyUSB0", "x" * 201])
def test_anything_else_is_refused_naming_the_url(url):
    assert refused(RobotConnect, {"url": url}) == [("url",)]


@pytest.mark.parametrize(
    ("field", "inside", "outside"),
    [
        ("baud", 1200, 1199),
        ("baud", 1_000_000, 1_000_001),
        ("tracker_port", 0, -1),
        ("tracker_port", 65535, 65536),
        ("natnet_command_port", 1, 0),
        ("natnet_command_port", 65535, 65536),
        ("natnet_rigid_body_id", 0, -1),
        ("natnet_rigid_body_id", MAX_ID, MAX_ID + 1),
        ("calibration_angle", 3.2, 3.21),
        ("calibration_angle", -3.2, -3.21),
        ("calibration_scale", 1e4, 1e4 + 1),
        ("calibration_scale", 1e-9, 0.0),
        ("tracker_protocol", "natnet", "vicon"),
    ],
)
def test_link_settings_outside_their_range_are_refused_naming_the_field(field, inside, outside):
    assert getattr(accepted(RobotConnect, CONNECT | {field: inside}), field) == inside
    assert refused(RobotConnect, CONNECT | {field: outside}) == [(field,)]


@pytest.mark.parametrize("address", ["0013A200DEADBEEF", "0x0013a200deadbeef"])
def test_a_robot_address_is_64_bits_of_hex(address):
    assert accepted(RobotConnect, CONNECT | {"robot_address": address}).robot_address == address


@pytest.mark.parametrize("address", ["0x12", "0013A200DEADBEEF00", "0013A200DEADBEEG", "0X0013A200DEADBEEF"])
def test_another_robot_address_is_refused(address):
    assert refused(RobotConnect, CONNECT | {"robot_address": address}) == [("robot_address",)]


@pytest.mark.parametrize("version", ["auto", "2.0", "3.1", "4.1", "4.2"])
def test_a_natnet_version_is_auto_or_one_the_reader_knows(version):
    assert accepted(RobotConnect, CONNECT | {"natnet_version": version}).natnet_version == version


@pytest.mark.parametrize(
    ("version", "why"),
    [("1.9", "2.0 to 4.x"), ("5.0", "2.0 to 4.x"), ("4", "MAJOR.MINOR"), ("latest", "MAJOR.MINOR")],
)
def test_an_unknown_natnet_version_is_refused_saying_what_is_known(version, why):
    body = CONNECT | {"natnet_version": version}
    assert refused(RobotConnect, body) == [("natnet_version",)]
    assert why in refusal_messages(RobotConnect, body)


@pytest.mark.parametrize("group", [None, "224.0.0.1", "239.255.42.99", "239.255.255.255"])
def test_a_natnet_stream_is_unicast_or_a_multicast_group(group):
    assert accepted(RobotConnect, CONNECT | {"natnet_multicast_group": group}).natnet_multicast_group == group


@pytest.mark.parametrize(
    ("group", "why"),
    [("10.0.0.1", "must be a multicast address"), ("240.0.0.1", "must be a multicast address"),
     ("lab-pc", "must be an IPv4 multicast address"), ("ff02::1", "must be an IPv4 multicast address")],
)  # fmt: skip
def test_a_group_that_is_not_ipv4_multicast_is_refused_saying_why(group, why):
    body = CONNECT | {"natnet_multicast_group": group}
    assert refused(RobotConnect, body) == [("natnet_multicast_group",)]
    assert why in refusal_messages(RobotConnect, body)


def test_calibration_origin_and_servo_limits_are_pairs_in_range():
    assert accepted(RobotConnect, CONNECT | {"calibration_origin": [1e4, -1e4]}).calibration_origin == [1e4, -1e4]
    assert refused(RobotConnect, CONNECT | {"calibration_origin": [0.0, 1e4 + 1]}) == [("calibration_origin", 1)]
    assert refused(RobotConnect, CONNECT | {"calibration_origin": [0.0]}) == [("calibration_origin",)]
    assert refused(RobotConnect, CONNECT | {"psi0_limits_deg": [10.0, 90.0]}) == [("psi0_limits_deg", 1)]
    assert refused(RobotConnect, CONNECT | {"zeta0_limits": [0.0, 0.98]}) == [("zeta0_limits", 0)]
    assert refused(RobotConnect, CONNECT | {"zeta0_limits": [0.7, 0.8, 0.9]}) == [("zeta0_limits",)]


def test_a_live_run_has_a_left_and_a_right_leg():
    assert len(accepted(RobotRunCreate, RUN).controls) == 2
    assert refused(RobotRunCreate, {"controls": [LEG]}) == [("controls",)]
    assert refused(RobotRunCreate, {"controls": [LEG] * 3}) == [("controls",)]
    assert refused(RobotRunCreate, {"controls": [LEG, LEG | {"psi0_deg": 90.0}]}) == [("controls", 1, "psi0_deg")]


@pytest.mark.parametrize(
    ("field", "inside", "outside"),
    [
        ("jumps", 1, 0),
        ("jumps", 10_000, 10_001),
        ("max_seconds", 3600.0, 3600.5),
        ("max_seconds", 1e-3, 0.0),
        ("experiment_id", 1, 0),
        ("operator", "o" * 80, "o" * 81),
        ("operator", "o", ""),
    ],
)
def test_a_live_run_is_bounded_in_jumps_and_time(field, inside, outside):
    assert getattr(accepted(RobotRunCreate, RUN | {field: inside}), field) == inside
    assert refused(RobotRunCreate, RUN | {field: outside}) == [(field,)]


@pytest.mark.parametrize(
    ("field", "inside", "outside"),
    [
        ("target_m", 2.0, 2.01),  # the chute's top
        ("target_m", 1e-3, 0.0),
        ("kp", 10.0, 10.01),
        ("ki", 0.0, -0.01),
        ("kd", 10.0, 10.01),
        ("zeta0_min", 0.01, 0.0),
        ("zeta0_max", 0.99, 1.0),
        ("zeta0_max", 0.81, 0.8),  # above zeta0_min
        ("controller", "deadbeat", "mpc"),
        ("climb_per_jump", 1.0, 0.0),
    ],
)
def test_a_closed_loops_gains_and_range_are_bounded_naming_the_field(field, inside, outside):
    body = {"target_m": 0.4}
    assert getattr(accepted(ClosedLoopIn, body | {field: inside}), field) == inside
    assert refused(ClosedLoopIn, body | {field: outside}) == [(field,)]
    assert refused(RobotRunCreate, RUN | {"closed_loop": body | {field: outside}}) == [("closed_loop", field)]


def test_a_closed_loop_needs_a_target_and_defaults_to_a_pd_law():
    loop = accepted(ClosedLoopIn, {"target_m": 0.4})
    assert (loop.kp, loop.ki, loop.kd, loop.zeta0_min, loop.zeta0_max) == (0.04, 0.0, 0.02, 0.80, 0.98)
    assert loop.controller == "pid", "today's loop unless another law is named"
    assert refused(ClosedLoopIn, {}) == [("target_m",)]


@pytest.mark.parametrize(("schema", "body"), [(RobotConnect, CONNECT), (RobotRunCreate, RUN)])
def test_unknown_fields_are_refused(schema, body):
    assert refused(schema, body | {"speed": 2}) == [("speed",)]


def test_the_estops_answer_is_the_status_with_the_acknowledgement():
    latch = EstopLatchOut(latched=True, acknowledged=False, since=1.7e9, reason="operator")
    answer = RobotEstopOut(
        state="estopped", url="loop://", robot_address="0x0013A200DEADBEEF", counters=None, estop=latch,
        last_delivery_failure=None, telemetry=None, tracker=None, run=None, transitions=[],
        acknowledged=True, latency_ms=4.2,
    )  # fmt: skip
    assert answer.acknowledged and answer.reason is None, "the estop's own reason only when not acknowledged"
    assert answer.estop.acknowledged is False, "the latch's acknowledgement is its own"
    assert RobotEstopOut.model_validate_json(answer.model_dump_json()) == answer
