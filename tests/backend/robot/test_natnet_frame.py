"""NatNet: frames of every version read as the SDK lays them out, bad packets refused and counted,
the pose source over unicast (with a fake server) and multicast, and the virtual robot's NatNet stream."""

import contextlib
import math
import socket
import struct
import time

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from pydantic import ValidationError

from backend.robot import natnet_source
from backend.robot.messages import Leg
from backend.robot.natnet import (
    NatNetError,
    connect_request,
    decode_frame,
    decode_server_info,
    encode_frame,
    keep_alive,
    parse_version,
)
from backend.robot.natnet_source import NatNetPoseSource
from backend.robot.touchdown import detect_touchdowns
from backend.robot.tracker import Calibration, UdpPoseSource
from backend.robot.virtual import VirtualRobot
from backend.schemas import RobotConnect
from backend.services.robot_tracker import open_tracker
from sim_core import LegControl, get_preset
from sim_core.errors import ParameterError
from sim_core.noise import NO_NOISE
from sim_core.walls import wall_of
from tests.backend.robot.natnet_frames import Body, Scene, frame_packet, server_info_packet
from tests.helpers import free_port
from tests.robot_rig import climb_open_loop

VERSIONS = [200, 201, 203, 205, 206, 207, 209, 210, 211, 300, 301, 400, 401]
PITCH = 0.3
BODIES = (
    Body(1, (0.1, 0.2, 0.05), (0.0, 0.0, 0.0, 1.0)),
    Body(2, (-0.25, 1.5, 0.02), (0.0, 0.0, math.sin(PITCH / 2), math.cos(PITCH / 2)), error=0.0007),
    Body(3, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0), markers=(), valid=False),
)
LEGS = {Leg.LEFT: (30.0, 0.87), Leg.RIGHT: (30.0, 0.9)}
ROBOT = get_preset("paper")
SCENE = Scene(frame=4321, timestamp=12.345678, bodies=BODIES)


def _version(v: int) -> tuple[int, int]:
    return divmod(v, 100)


def _packets():
    return [(v, frame_packet(SCENE, v)) for v in VERSIONS]


@pytest.mark.parametrize("v", VERSIONS)
def test_a_frame_of_every_version_gives_its_rigid_bodies(v):
    frame = decode_frame(frame_packet(SCENE, v), _version(v))
    assert frame.number == 4321
    assert frame.timestamp == pytest.approx(12.345678, abs=1e-12 if v >= 207 else 1e-6), "f32 before 2.7"
    assert [body.id for body in frame.rigid_bodies] == [1, 2, 3], "the skeleton's bodies are not the frame's"
    body = frame.rigid_body(2)
    assert body.position == pytest.approx((-0.25, 1.5, 0.02), abs=1e-7)
    assert body.angle_about_z == pytest.approx(PITCH, abs=1e-6)
    assert body.mean_error == pytest.approx(0.0007)
    assert [b.tracked for b in frame.rigid_bodies] == [True, True, v < 206], "no tracking flag before 2.6"
    assert frame.rigid_body(99) is None


@pytest.mark.parametrize("v", VERSIONS)
def test_the_production_encoder_agrees_with_the_published_layout(v):
    """The virtual robot's frames: the test encoder's bytes for a scene holding just that body."""
    body = BODIES[1]
    ours = encode_frame(77, 1.25, decode_frame(frame_packet(SCENE, v), _version(v)).rigid_body(2), _version(v))
    alone = Scene(
        77,
        1.25,
        (Body(2, body.position, body.quaternion, markers=(), error=0.0007),),
        marker_sets=(),
        unlabeled=0,
        skeletons=(),
        assets=(),
        labeled=0,
        force_plates=(),
        devices=(),
    )
    theirs = frame_packet(alone, v, end_tag=0)
    # The suffix's latency, timecode and stamps differ (the robot's camera has none): compare up to them.
    latency = 4 if v < 300 else 0
    suffix = latency + 8 + (8 if v >= 207 else 4) + (24 if v >= 300 else 0) + (8 if v >= 401 else 0) + 2 + 4
    assert ours[4:-suffix] == theirs[4:-suffix] and len(ours) == len(theirs)
    assert ours[-6:] == theirs[-6:] == bytes(6), "zero parameters and a zero end-of-data tag"
    assert decode_frame(ours, _version(v)).timestamp == pytest.approx(1.25)


END_TAGS = (0, 0xFFFFFFFF)  # the SDK reads the tag and never checks its value
FRAMES_PER_VERSION = 100


@pytest.mark.parametrize("v", VERSIONS)
def test_frames_ending_with_the_end_of_data_tag_decode_as_without_it(v):
    """PacketClient.cpp reads a u32 end-of-data tag after the frame parameters: Motive's frames carry it."""
    decoded = 0
    for k in range(FRAMES_PER_VERSION):
        scene = Scene(4321 + k, 12.345678 + k / 100, BODIES)
        plain = decode_frame(frame_packet(scene, v), _version(v))
        for tag in END_TAGS:
            tagged = decode_frame(frame_packet(scene, v, end_tag=tag), _version(v))
            assert tagged == plain, f"frame {scene.frame}, tag {tag:#x}"
            decoded += 1
    assert decoded == FRAMES_PER_VERSION * len(END_TAGS)


@pytest.mark.parametrize("extra", [1, 2, 3, 5, 6, 7, 9])
def test_bytes_after_the_frame_other_than_the_tag_are_refused(extra):
    for v, packet in _packets():
        longer = packet + bytes(extra)
        with pytest.raises(NatNetError, match="end-of-data tag"):
            decode_frame(struct.pack("<HH", 7, len(longer) - 4) + longer[4:], _version(v))


def test_every_truncation_of_every_version_is_refused():
    """Every cut of a frame is refused, tagged or not, but the one that takes off exactly the tag."""
    cases = 0
    for v in VERSIONS:
        for packet in (frame_packet(SCENE, v), frame_packet(SCENE, v, end_tag=0)):
            for n in range(len(packet)):
                cut = packet[:n]
                with pytest.raises(NatNetError):
                    decode_frame(cut, _version(v))
                if n >= 4 and cut[4:] != frame_packet(SCENE, v)[4:]:
                    # The header fixed to match: the frame's own structure must catch it.
                    with pytest.raises(NatNetError):
                        decode_frame(struct.pack("<HH", 7, n - 4) + cut[4:], _version(v))
                cases += 2
    assert cases > 10000


def test_a_frame_read_with_the_wrong_version_is_refused():
    """All pairs but 2.6 and 2.7: their frames differ only in the timestamp's size (f32, f64), by 4 bytes,
    as much as the optional end-of-data tag, so a configured version must name the stream's exactly."""
    alike = {(206, 207), (207, 206)}
    for v in VERSIONS:
        for tag in (None, *END_TAGS):
            packet = frame_packet(SCENE, v, end_tag=tag)
            for other in VERSIONS:
                same_layout = frame_packet(SCENE, other) == frame_packet(SCENE, v)
                if not same_layout and (v, other) not in alike:
                    with pytest.raises(NatNetError):
                        decode_frame(packet, _version(other))


def test_a_4_1_block_size_that_does_not_match_is_refused():
    packet = bytearray(frame_packet(SCENE, 401))
    # The marker set block: frame number (4), count (4), then its size.
    struct.pack_into("<I", packet, 12, struct.unpack_from("<I", packet, 12)[0] + 1)
    with pytest.raises(NatNetError, match="marker set block says"):
        decode_frame(bytes(packet), (4, 1))


@settings(max_examples=300, deadline=None)
@given(st.binary(max_size=400), st.sampled_from(VERSIONS))
def test_random_bytes_never_crash_the_decoder(data, v):
    for packet in (data, struct.pack("<HH", 7, len(data)) + data):
        with contextlib.suppress(NatNetError):
            decode_frame(packet, _version(v))


@settings(max_examples=300, deadline=None)
@given(st.sampled_from(VERSIONS), st.data())
def test_corrupted_frames_never_crash_the_decoder(v, data):
    packet = bytearray(frame_packet(SCENE, v))
    for _ in range(data.draw(st.integers(1, 4))):
        packet[data.draw(st.integers(4, len(packet) - 1))] = data.draw(st.integers(0, 255))
    try:
        frame = decode_frame(bytes(packet), _version(v))
    except NatNetError:
        return
    assert len(frame.rigid_bodies) <= len(packet) // 32


def test_server_info_and_requests():
    old = decode_server_info(server_info_packet("Tracking Tools", (2, 5, 0, 0), (2, 5, 0, 0)))
    new = decode_server_info(server_info_packet("Motive", (3, 1, 0, 0), (4, 1, 0, 0)))
    assert (old.application, old.natnet_version) == ("Tracking Tools", (2, 5, 0, 0))
    assert (new.application, new.application_version, new.natnet_version) == ("Motive", (3, 1, 0, 0), (4, 1, 0, 0))
    with pytest.raises(NatNetError):
        decode_server_info(server_info_packet("Motive", (3, 1, 0, 0), (4, 1, 0, 0))[:-1])
    request = connect_request((4, 1))
    assert struct.unpack_from("<HH", request) == (0, 271) and len(request) == 275
    assert request[4:8] == b"Ping" and request[4 + 265 : 4 + 269] == bytes([4, 1, 0, 0])
    assert connect_request()[4 + 265 : 4 + 269] == bytes(4), "zeros: the server's own version"
    assert keep_alive() == struct.pack("<HH", 10, 0) + b"\0"


@pytest.mark.parametrize(
    ("text", "ok"),
    [("2.5", (2, 5)), ("4.1", (4, 1)), ("4.2", (4, 2)), ("1.9", None), ("5.0", None), ("3", None), ("x.1", None)],
)
def test_versions_are_checked(text, ok):
    if ok:
        assert parse_version(text) == ok
    else:
        with pytest.raises(ParameterError, match="natnet_version"):
            parse_version(text)


def _until(condition, timeout=3.0):
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
        # Connected: keep-alives every REQUEST_EVERY, no more connects.
        assert server.recvfrom(1024)[0] == keep_alive()
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
            for frame in range(1, 101):
                server.sendto(frame_packet(_scene(frame), 401, end_tag=0), client)
            _until(lambda: source.stats.received == 100)
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
