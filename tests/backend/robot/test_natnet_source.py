"""Poses from the camera software's NatNet stream (backend/robot/natnet_source.py): the source over
unicast (with a fake server) and multicast, what it takes from whom, how it counts (a malformed packet
once, never also as dropped; PKT1 alike), the virtual robot's NatNet stream seen as its PKT1 one is,
and the connect options that open it."""

import contextlib
import math
import socket
import struct
import time

import pytest
from pydantic import ValidationError

from backend.robot import natnet_source
from backend.robot.messages import Leg
from backend.robot.natnet import connect_request, keep_alive
from backend.robot.natnet_frame import RigidBody, encode_frame
from backend.robot.natnet_source import NatNetPoseSource
from backend.robot.touchdown import detect_touchdowns
from backend.robot.tracker import Calibration, Pose, UdpPoseSource, encode_datagram
from backend.robot.virtual import VirtualRobot
from backend.schemas import RobotConnect
from backend.services.robot_tracker import open_tracker
from sim_core import LegControl, get_preset
from sim_core.model.noise import NO_NOISE
from sim_core.model.walls import wall_of
from tests.backend.robot.natnet_frames import BODIES, PITCH, Scene, frame_packet, server_info_packet
from tests.helpers import free_port
from tests.robot_rig import climb_open_loop

LEGS = {Leg.LEFT: (30.0, 0.87), Leg.RIGHT: (30.0, 0.9)}
ROBOT = get_preset("paper")


def _until(condition, timeout=10.0):  # a bound on waiting for the reader thread, not a timing assertion
    deadline = time.monotonic() + timeout
    while not condition():
        assert time.monotonic() < deadline, "timed out"
        time.sleep(0.01)


def _scene(frame, bodies=BODIES):
    return Scene(frame, 100.0 + frame / 100, bodies)


def test_unicast_source_connects_learns_the_version_and_counts(monkeypatch):
    monkeypatch.setattr(natnet_source, "REQUEST_EVERY", 0.1)
    server = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    server.bind(("127.0.0.1", 0))
    server.settimeout(3.0)
    source = NatNetPoseSource(
        2,
        interface="127.0.0.1",
        port=0,
        multicast_group=None,
        server=server.getsockname(),
        calibration=Calibration(origin=(-0.5, 0.0)),
    )
    try:
        request, client = server.recvfrom(1024)
        assert request == connect_request() and client == source.address, "the connect comes from the data socket"
        server.sendto(frame_packet(_scene(1), 209), client)  # before the version is known: ignored
        _until(lambda: source.stats.ignored == 1)
        server.sendto(server_info_packet("Motive", (1, 10, 0, 0), (2, 9, 0, 0)), client)
        _until(lambda: source.version == "2.9")
        assert (source.protocol, source.error, source.server_info_refused) == ("natnet", None, 0)
        for frame in (2, 3, 6):  # 4 and 5 lost; ended with the end-of-data tag, as Motive sends them
            server.sendto(frame_packet(_scene(frame), 209, end_tag=0), client)
        server.sendto(frame_packet(_scene(7, BODIES[:1]), 209), client)  # body 2 not seen
        server.sendto(frame_packet(_scene(8), 209)[:-3], client)  # truncated
        server.sendto(b"\x07\x00", client)
        server.sendto(b"\x08\x00\x03\x00abc", client)  # a message string: no pose, not malformed
        _until(lambda: source.stats.malformed == 2 and source.stats.ignored == 2)
        assert (source.stats.received, source.stats.dropped) == (4, 2)
        pose = source.latest()
        assert pose.time == pytest.approx(100.06) and pose.pitch == pytest.approx(PITCH, abs=1e-6)
        assert (pose.x, pose.y) == pytest.approx((0.25, 1.5), abs=1e-6), "calibrated as PKT1 poses are"
        # Connected: keep-alives every REQUEST_EVERY, no more connects. Connects sent before the
        # answer was read may still wait in the server's socket (a loaded machine reads late): the
        # source sends from one thread, so they all come before its first keep-alive.
        before, deadline = [], time.monotonic() + 10.0  # a hang guard: connects for ever would be one
        while (request := server.recvfrom(1024)[0]) != keep_alive():
            before.append(request)
            assert time.monotonic() < deadline, f"no keep-alive, {len(before)} connects"
        assert set(before) <= {connect_request()}, before
        assert server.recvfrom(1024)[0] == keep_alive(), "no connect after the first keep-alive"
    finally:
        source.close()
        server.close()


@contextlib.contextmanager
def _fake_server(monkeypatch, rigid_body_id=2):
    """A unicast source and the NatNet server it asks (a socket on 127.0.0.1), once its first connect
    request has arrived there: ``(source, server, client address)``."""
    monkeypatch.setattr(natnet_source, "REQUEST_EVERY", 0.1)
    server = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    server.bind(("127.0.0.1", 0))
    server.settimeout(3.0)
    source = NatNetPoseSource(
        rigid_body_id, interface="127.0.0.1", port=0, multicast_group=None, server=server.getsockname()
    )
    try:
        _request, client = server.recvfrom(1024)
        yield source, server, client
    finally:
        source.close()
        server.close()


def _info(version: tuple[int, int]) -> bytes:
    return server_info_packet("Motive", (3, 1, 0, 0), (*version, 0, 0))


def test_server_info_is_taken_only_from_the_server_and_only_once(monkeypatch):
    stranger = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    stranger.bind(("127.0.0.1", 0))  # the server's host, another port
    with _fake_server(monkeypatch) as (source, server, client):
        try:
            stranger.sendto(_info((2, 0)), client)
            _until(lambda: source.server_info_refused == 1)
            assert source.version is None and source.server_info is None, "a stranger's answer is not taken"
            server.sendto(_info((4, 1)), client)
            _until(lambda: source.version == "4.1")
            server.sendto(_info((2, 0)), client)  # a stray second answer from the server itself
            _until(lambda: source.server_info_refused == 2)
            assert source.version == "4.1" and source.error is None
            for frame in range(1, 101):  # paced: a burst of datagrams may overflow a loaded machine's socket buffer
                server.sendto(frame_packet(_scene(frame), 401, end_tag=0), client)
                _until(lambda frame=frame: source.stats.received == frame)
            assert (source.stats.malformed, source.stats.ignored, source.stats.dropped) == (0, 0, 0)
        finally:
            stranger.close()


def test_server_info_before_any_request_is_not_taken(monkeypatch):
    """The server's name does not resolve, so no connect request goes out: nothing is awaited."""

    def unresolvable(host):
        raise socket.gaierror(f"{host}: no such host")

    monkeypatch.setattr(natnet_source.socket, "gethostbyname", unresolvable)
    server = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    server.bind(("127.0.0.1", 0))
    source = NatNetPoseSource(2, interface="127.0.0.1", port=0, multicast_group=None, server=server.getsockname())
    try:
        server.sendto(_info((4, 1)), source.address)
        _until(lambda: source.server_info_refused == 1)
        assert source.version is None and source.server_info is None
    finally:
        source.close()
        server.close()


@pytest.mark.parametrize(("reported", "says"), [((200, 7), "200.7"), ((1, 9), "1.9"), ((5, 0), "5.0")])
def test_a_version_this_reader_does_not_know_is_an_error_not_a_guess(monkeypatch, reported, says):
    with _fake_server(monkeypatch) as (source, server, client):
        server.sendto(_info(reported), client)
        _until(lambda: source.error is not None)
        assert source.error == f"NatNet server Motive reports version {says}; this reader knows 2.0 to 4.x"
        assert source.version is None
        server.sendto(frame_packet(_scene(1), 401, end_tag=0), client)
        _until(lambda: source.stats.ignored == 1)
        assert (source.stats.received, source.stats.malformed) == (0, 0), "no frame read with a guessed layout"
        assert source.server_info.natnet_version[:2] == reported, "answered: no more connect requests"


def test_a_configured_version_wins_and_needs_no_answer():
    source = NatNetPoseSource(
        1, interface="127.0.0.1", port=0, multicast_group=None, server=("127.0.0.1", 9), version=(2, 5)
    )
    sender = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    try:
        sender.sendto(frame_packet(_scene(1), 205), source.address)
        _until(lambda: source.stats.received == 1)
        assert source.latest().x == pytest.approx(0.1)
    finally:
        sender.close()
        source.close()


def test_a_configured_version_is_asked_for_and_kept_whatever_the_server_says(monkeypatch, caplog):
    monkeypatch.setattr(natnet_source, "REQUEST_EVERY", 0.1)
    server = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    server.bind(("127.0.0.1", 0))
    server.settimeout(3.0)
    source = NatNetPoseSource(
        2, interface="127.0.0.1", port=0, multicast_group=None, server=server.getsockname(), version=(2, 9)
    )
    try:
        request, client = server.recvfrom(1024)
        assert request == connect_request((2, 9)), "the connect asks for the configured version"
        with caplog.at_level("WARNING", logger="parkourlab.robot"):
            server.sendto(_info((3, 1)), client)
            _until(lambda: source.server_info is not None)
        assert (source.version, source.error) == ("2.9", None), "read as configured, not as the server says"
        assert any("streams 3.1; reading it as the configured 2.9" in r.getMessage() for r in caplog.records)
        server.sendto(frame_packet(_scene(1), 209), client)
        _until(lambda: source.stats.received == 1)
        assert source.latest().pitch == pytest.approx(PITCH, abs=1e-6)
    finally:
        source.close()
        server.close()


def _configured_source(rigid_body_id: int) -> NatNetPoseSource:
    return NatNetPoseSource(
        rigid_body_id, interface="127.0.0.1", port=0, multicast_group=None, server=("127.0.0.1", 9), version=(3, 1)
    )


def test_a_non_finite_pose_is_malformed_and_never_a_pose():
    source = _configured_source(5)
    sender = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    try:
        for frame, x in ((1, math.nan), (2, math.inf), (3, 0.25)):
            body = RigidBody(5, (x, 1.0, 0.0), (0.0, 0.0, 0.0, 1.0))
            sender.sendto(encode_frame(frame, frame / 100, body, (3, 1)), source.address)
        _until(lambda: source.stats.received == 1)
        assert (source.stats.malformed, source.stats.ignored) == (2, 0)
        assert [pose.x for pose in source.poses_from(0)] == [0.25], "only the finite pose was kept"
    finally:
        sender.close()
        source.close()


def test_an_untracked_body_is_a_frame_received_but_no_pose():
    source = _configured_source(3)  # BODIES[2]: tracking lost (2.6+)
    sender = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    try:
        sender.sendto(frame_packet(_scene(1), 301), source.address)
        _until(lambda: source.stats.ignored == 1)
        assert (source.stats.received, source.stats.malformed) == (1, 0), "the frame counts: no loss"
        assert source.latest() is None
    finally:
        sender.close()
        source.close()


def test_multicast_source_joins_the_group():
    port = free_port(socket.SOCK_DGRAM)
    try:
        source = NatNetPoseSource(2, interface="127.0.0.1", port=port, server=("127.0.0.1", 9), version=(3, 1))
    except OSError as error:
        pytest.skip(f"no multicast on this host's loopback: {error}")
    sender = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    try:
        sender.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_IF, socket.inet_aton("127.0.0.1"))
        sender.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_LOOP, 1)
        for frame in (1, 2):
            sender.sendto(frame_packet(_scene(frame), 301), ("239.255.42.99", port))
        _until(lambda: source.stats.received == 2)
        assert source.latest().y == pytest.approx(1.5)
    finally:
        sender.close()
        source.close()


def _stream(source, packets) -> None:
    """``packets`` to ``source``, paced so that loopback's buffer never drops one; back once all are counted."""
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sender:
        for k, packet in enumerate(packets, 1):
            sender.sendto(packet, source.address)
            if k % 20 == 0 or k == len(packets):
                _until(lambda k=k: source.stats.received + source.stats.malformed == k)


@pytest.mark.parametrize("v", [209, 301, 401])
@pytest.mark.parametrize("latency", [True, False], ids=["sdk-latency", "no-latency"])
def test_a_stream_with_and_without_the_end_of_data_tag_loses_nothing(v, latency):
    """As measured with an independent sender: 300 frames, every third without the tag. A 2.9 one
    written without the 2.x software latency (as NatNetClient.py 3.x/4.x reads 2.x) was refused when
    untagged (malformed 100, dropped 99: loss 0.33) and, tagged, read with a timestamp 4 bytes off."""
    source = NatNetPoseSource(
        2, interface="127.0.0.1", port=0, multicast_group=None, server=("127.0.0.1", 9), version=divmod(v, 100)
    )
    try:
        _stream(source, [frame_packet(_scene(k), v, None if k % 3 == 0 else 0, latency=latency) for k in range(1, 301)])
        counts = source.stats.snapshot()
        assert (counts.received, counts.malformed, counts.dropped, counts.loss) == (300, 0, 0, 0.0)
        assert [pose.time for pose in source.poses_from(0)] == [_scene(k).timestamp for k in range(1, 301)]
    finally:
        source.close()


LOST = {5, 17}  # never sent: real gaps
BAD_NATNET = {  # sent malformed in place of the frame of that number
    3: lambda p: struct.pack("<HH", 7, len(p) - 7) + p[4:-3],  # cut, the header fixed to match
    8: lambda p: p[:-3],  # cut: the header says more
    12: lambda p: frame_packet(_scene(2_000_000_000), 301)[:-1],  # a far number, cut: no restart either
    13: lambda p: p[:-1],  # two in a row
    21: lambda p: b"\x07\x00\x02\x00ab",
}


def test_natnet_malformed_frames_are_counted_once_never_also_as_dropped():
    source = _configured_source(2)
    try:
        numbers = [k for k in range(1, 31) if k not in LOST]
        nan = encode_frame(9, 0.09, RigidBody(2, (math.nan, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0)), (3, 1))
        bad = {**{k: make(frame_packet(_scene(k), 301)) for k, make in BAD_NATNET.items()}, 9: nan}
        _stream(source, [bad.get(k, frame_packet(_scene(k), 301)) for k in numbers])
        counts = source.stats.snapshot()
        assert (counts.received, counts.malformed, counts.dropped, counts.restarts) == (22, 6, 2, 0)
        assert counts.loss == pytest.approx(2 / 24), "from the real gaps only"
        assert len(source.poses_from(0)) == 22
    finally:
        source.close()


def test_pkt1_malformed_datagrams_are_counted_once_never_also_as_dropped():
    source = UdpPoseSource()
    try:
        good = {k: encode_datagram(k, Pose(k / 100, 0.0, 0.5)) for k in range(1, 31) if k not in LOST}
        bad = {3: good[3][:-1], 4: encode_datagram(4, Pose(math.nan, 0.0, 0.5)), 20: b"x" * 40, 21: b"?"}
        _stream(source, [bad.get(k, datagram) for k, datagram in good.items()])
        counts = source.stats.snapshot()
        assert (counts.received, counts.malformed, counts.dropped, counts.restarts) == (24, 4, 2, 0)
        assert counts.loss == pytest.approx(2 / 26)
    finally:
        source.close()


def _climb(tracker, protocol: str, jumps: int = 8):
    """An open-loop climb of the noiseless virtual robot at 6x real time, its camera on ``protocol``
    (tracker noise and dropped frames as usual, from the same seed): the touchdowns its tracker saw."""
    robot = VirtualRobot(
        tracker_to=tracker.address,
        noise=NO_NOISE,
        speed=6.0,
        seed=1,
        tracker_protocol=protocol,
        natnet_version="2.9",
        natnet_rigid_body_id=3,
    ).start()
    try:
        climb_open_loop(robot, LEGS, jumps)
    finally:
        robot.stop()
        tracker.close()
    poses = tracker.as_arrays()
    leg_for = lambda k: LegControl.from_degrees(*LEGS[Leg.of(wall_of(k + 1))])  # noqa: E731
    return detect_touchdowns(poses["time"], poses["x"], poses["y"], ROBOT, leg_for), tracker.stats, robot.climber


def test_a_live_climb_over_natnet_sees_the_touchdowns_pkt1_sees():
    over_pkt1, pkt1_stats, _ = _climb(UdpPoseSource(), "pkt1")
    natnet = NatNetPoseSource(
        3, interface="127.0.0.1", port=0, multicast_group=None, server=("127.0.0.1", 9), version=(2, 9)
    )
    over_natnet, stats, climber = _climb(natnet, "natnet")
    common = min(len(over_pkt1), len(over_natnet))
    assert common >= 6, (len(over_pkt1), len(over_natnet))
    # The same seed streams the same poses; NatNet's f32 positions differ from PKT1's f64 by ~1e-7 m,
    # and a pose lost to real-time jitter (a late frame) moves a fitted touchdown by far less than 1e-3.
    for ours, theirs in zip(over_natnet[:common], over_pkt1[:common], strict=True):
        assert ours.wall == theirs.wall
        assert ours.time == pytest.approx(theirs.time, abs=1e-3)
        assert ours.state == pytest.approx(theirs.state, abs=1e-3)
    assert stats.malformed == 0 and stats.ignored == 0
    assert stats.dropped == pytest.approx(climber.frames_dropped, abs=2), "the robot's dropped frames, seen as gaps"
    assert abs(stats.loss - pkt1_stats.loss) < 0.02


@pytest.mark.parametrize(
    ("field", "value", "says"),
    [
        ("tracker_protocol", "vrpn", "'pkt1' or 'natnet'"),
        ("natnet_version", "1.5", "from 2.0 to 4.x"),
        ("natnet_version", "latest", "MAJOR.MINOR"),
        ("natnet_multicast_group", "10.0.0.1", "multicast address"),
        ("natnet_multicast_group", "239.255.42", "IPv4 multicast address"),
        ("natnet_rigid_body_id", -1, "greater than or equal to 0"),
        ("natnet_command_port", 0, "greater than or equal to 1"),
    ],
)
def test_connect_options_are_checked_naming_the_field(field, value, says):
    with pytest.raises(ValidationError) as raised:
        RobotConnect(url="loop://", **{field: value})
    [error] = raised.value.errors()
    assert error["loc"] == (field,) and says in error["msg"]


def test_connect_opens_the_tracker_it_names():
    body = RobotConnect(
        url="loop://",
        tracker_protocol="natnet",
        tracker_port=0,
        natnet_multicast_group=None,
        natnet_version="2.5",
        natnet_rigid_body_id=4,
        natnet_server_host="127.0.0.1",
        calibration_scale=0.001,
    )
    tracker = open_tracker(body)
    try:
        assert isinstance(tracker, NatNetPoseSource) and tracker.version == "2.5" and tracker.rigid_body_id == 4
        assert tracker.multicast_group is None and tracker.server == ("127.0.0.1", 1510)
        assert tracker.calibration.scale == 0.001
    finally:
        tracker.close()
    pkt1 = open_tracker(RobotConnect(url="loop://", tracker_port=0))
    pkt1.close()
    assert isinstance(pkt1, UdpPoseSource)
