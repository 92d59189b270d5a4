"""NatNet frames of data (backend/robot/natnet_frame.py): every version read as the SDK lays it out,
the production encoder agreeing with the published layout, and bad packets refused, never crashing."""

import contextlib
import itertools
import math
import struct

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from backend.robot.natnet import NatNetError
from backend.robot.natnet_frame import RigidBody, decode_frame, encode_frame, quaternion_about_z
from tests.backend.robot.natnet_frames import BODIES, PITCH, VERSIONS, Body, Scene, frame_packet

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
    as much as the optional end-of-data tag, so a configured version must name the stream's exactly.
    2.x frames without the software latency alike."""
    alike = {(206, 207), (207, 206)}
    for v in VERSIONS:
        for tag, latency in itertools.product((None, *END_TAGS), (True, False)):
            packet = frame_packet(SCENE, v, end_tag=tag, latency=latency)
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


@pytest.mark.parametrize("angle", [0.0, 0.3, -1.2, math.pi - 1e-9, -math.pi + 1e-9])
def test_a_pitch_written_as_a_quaternion_reads_back_as_the_angle_about_z(angle):
    body = RigidBody(5, (0.0, 0.0, 0.0), quaternion_about_z(angle))
    assert body.angle_about_z == pytest.approx(angle, abs=1e-12)
    assert math.fsum(q * q for q in body.orientation) == pytest.approx(1.0), "a unit quaternion"


def test_an_unknown_pitch_is_the_identity_rotation():
    assert quaternion_about_z(math.nan) == (0.0, 0.0, 0.0, 1.0)


@pytest.mark.parametrize("v", VERSIONS)
def test_an_encoded_body_reads_back_as_it_was_written(v):
    """What the virtual robot's camera sends is what the pose source reads: the frame number (to 32
    bits), the timestamp and the body (its tracking flag from 2.6 on)."""
    body = RigidBody(7, (0.5, -0.25, 0.125), quaternion_about_z(0.5), tracked=False)
    frame = decode_frame(encode_frame(2**32 + 9, 3.5, body, _version(v)), _version(v))
    assert (frame.number, frame.timestamp, [b.id for b in frame.rigid_bodies]) == (9, 3.5, [7])
    [read] = frame.rigid_bodies
    assert read.position == body.position and read.orientation == pytest.approx(body.orientation, abs=1e-7)
    assert read.tracked is (v < 206), "no tracking flag before 2.6: tracked"
    assert read.mean_error == 0.0, "an unknown (NaN) mean error is sent as 0"


def _f32(x: float) -> float:
    return struct.unpack("<f", struct.pack("<f", x))[0]


_F32 = st.floats(-100.0, 100.0, width=32)
_BODIES = st.lists(
    st.builds(
        Body,
        id=st.integers(0, 2**31 - 1),
        position=st.tuples(_F32, _F32, _F32),
        quaternion=st.tuples(_F32, _F32, _F32, _F32),
        markers=st.lists(st.tuples(_F32, _F32, _F32), max_size=3).map(tuple),
        error=st.floats(0.0, 2**-7, width=32),
        valid=st.booleans(),
    ),
    max_size=4,
    unique_by=lambda body: body.id,
).map(tuple)


@pytest.mark.parametrize("v", VERSIONS)
@settings(max_examples=60, deadline=None)
@given(
    bodies=_BODIES,
    number=st.integers(0, 2**31 - 1),
    timestamp=st.just(0.0) | st.floats(1e-3, 1e7),
    tag=st.sampled_from((None, *END_TAGS)),
    latency=st.booleans(),
)
def test_any_frame_of_any_version_reads_back_with_or_without_the_tag_and_the_2x_latency(
    v, bodies, number, timestamp, tag, latency
):
    """Every version, with and without the end-of-data tag, a 2.x frame with the SDK's software latency
    (PacketClient.cpp) and without it (NatNetClient.py 3.x/4.x, the ``natnet`` package): the frame
    number, the timestamp (f32 before 2.7) and every rigid body as written. Without latency and tag a
    2.x frame used to be refused as truncated; with the tag, its timestamp was read 4 bytes off."""
    frame = decode_frame(frame_packet(Scene(number, timestamp, bodies), v, tag, latency=latency), _version(v))
    assert frame.number == number
    assert frame.timestamp == (timestamp if v >= 207 else _f32(timestamp))
    assert [body.id for body in frame.rigid_bodies] == [body.id for body in bodies]
    for read, body in zip(frame.rigid_bodies, bodies, strict=True):
        assert (read.position, read.orientation) == (body.position, body.quaternion)
        assert read.mean_error == body.error if v >= 200 else math.isnan(read.mean_error)
        assert read.tracked is (body.valid or v < 206)


@pytest.mark.parametrize("v", [v for v in VERSIONS if v < 300])
def test_a_2x_frame_without_the_latency_is_cut_like_any_other(v):
    """Without the latency, as with it: a cut of a frame is refused (the header fixed to match), but the
    one that takes off exactly the tag; and bytes after it other than a tag are refused."""
    plain = frame_packet(SCENE, v, latency=False)
    assert decode_frame(plain, _version(v)) == decode_frame(frame_packet(SCENE, v), _version(v))
    tagged = frame_packet(SCENE, v, 0, latency=False)
    for n in range(4, len(tagged)):
        if tagged[4:n] != plain[4:]:
            with pytest.raises(NatNetError):
                decode_frame(struct.pack("<HH", 7, n - 4) + tagged[4:n], _version(v))
    for extra in (1, 2, 3, 5, 6, 7, 9):
        with pytest.raises(NatNetError, match="end-of-data tag"):
            decode_frame(struct.pack("<HH", 7, len(plain) - 4 + extra) + plain[4:] + bytes(extra), _version(v))
