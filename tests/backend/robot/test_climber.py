"""The virtual robot's body (backend/robot/climber.py): what its camera streams (PKT1 datagrams or
NatNet frames of one rigid body), the same climb from the same seed, options checked by name; and in
an open-loop run of the virtual robot its tracked touchdowns follow the map of its true physics,
until it falls or reaches the floor and says so."""

import itertools
import socket
from dataclasses import replace

import numpy as np
import pytest

from backend.robot.climber import Climber
from backend.robot.link import LinkState
from backend.robot.messages import Fault, Leg
from backend.robot.natnet_frame import decode_frame
from backend.robot.touchdown import detect_touchdowns, height_gains
from backend.robot.tracker import UdpPoseSource, decode_datagram
from backend.robot.virtual import VirtualRobot
from sim_core import ClimbEnd, ControlSchedule, LegControl, PhysicalParams, get_preset, iterate_map
from sim_core.climb.records import FLOOR
from sim_core.model.controls import LegOffsets
from sim_core.model.errors import ParameterError
from sim_core.model.failures import Failure
from sim_core.model.noise import NO_NOISE, NoiseModel
from sim_core.model.walls import Wall, wall_of
from sim_core.world.world import Side, World
from tests.robot_rig import climb_open_loop

LEGS = {Leg.LEFT: (30.0, 0.87), Leg.RIGHT: (30.0, 0.9)}
ROBOT = get_preset("paper")
FRAMES = 40  # datagrams read from each camera: 0.4 s of climb
RECEIVE_TIMEOUT_S = 30.0  # [s] the first climb may wait for the kernels to load: generous, not a latency claim


def _streamed(frames: int = FRAMES, **options) -> list[bytes]:
    """The first ``frames`` datagrams a running climber's camera sends (at 20x real time)."""
    camera = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    camera.bind(("127.0.0.1", 0))
    camera.settimeout(RECEIVE_TIMEOUT_S)
    options = {"noise": NO_NOISE, "speed": 20.0, "seed": 1} | options
    climber = Climber(lambda: LEGS, lambda: True, lambda: None, camera.getsockname(), **options).start()
    try:
        return [camera.recv(65536) for _ in range(frames)]
    finally:
        climber.stop()
        camera.close()


def test_the_camera_streams_pkt1_datagrams_numbered_from_one():
    received = [decode_datagram(data) for data in _streamed(drop_rate=0.0)]
    assert [frame for frame, _pose in received] == list(range(1, FRAMES + 1)), "none dropped: every number"
    times = [pose.time for _frame, pose in received]
    assert all(later > earlier for earlier, later in itertools.pairwise(times)), "the climb's clock"


def test_a_natnet_camera_streams_the_same_poses_as_one_rigid_body():
    """The protocol changes the encoding only: NatNet frames of body ``natnet_rigid_body_id`` carry
    the PKT1 poses of the same seed (positions as f32)."""
    same = {"drop_rate": 0.0, "tracker_noise": 0.001}
    pkt1 = [decode_datagram(data) for data in _streamed(**same)]
    natnet = [
        decode_frame(data, (2, 9)) for data in _streamed(tracker_protocol="natnet", natnet_version="2.9",
                                                          natnet_rigid_body_id=3, **same)
    ]  # fmt: skip
    for (number, pose), frame in zip(pkt1, natnet, strict=True):
        [body] = frame.rigid_bodies
        assert (frame.number, body.id, body.tracked) == (number, 3, True)
        assert frame.timestamp == pose.time, "f64 timestamps from NatNet 2.7"
        assert body.position == pytest.approx((pose.x, pose.y, 0.0), abs=1e-6), "the table plane is x–y"


def test_the_same_seed_climbs_and_is_seen_the_same_way():
    noisy = {"tracker_noise": 0.002, "drop_rate": 0.1}
    first = _streamed(seed=5, **noisy)
    assert _streamed(seed=5, **noisy) == first, "tracker noise and dropped frames drawn from the seed"
    assert _streamed(seed=6, **noisy) != first


@pytest.mark.parametrize(
    ("option", "value", "field"),
    [
        ("tracker_protocol", "vrpn", "tracker_protocol"),
        ("natnet_version", "1.9", "natnet_version"),
        ("natnet_rigid_body_id", -1, "natnet_rigid_body_id"),
        ("tracker_noise", 0.5, "tracker_noise"),
        ("drop_rate", 1.5, "drop_rate"),
        ("speed", 0.0, "speed"),
    ],
)
def test_options_are_checked_naming_the_field(option, value, field):
    with pytest.raises(ParameterError) as raised:
        Climber(lambda: LEGS, lambda: True, lambda: None, ("127.0.0.1", 9), **{option: value})
    assert raised.value.field == field


def _run(noise, jumps, *, speed=6.0, seed=1, legs=LEGS, **climber_options):
    tracker = UdpPoseSource()
    robot = VirtualRobot(tracker_to=tracker.address, noise=noise, speed=speed, seed=seed, **climber_options).start()
    try:
        state_at_end, link = climb_open_loop(robot, legs, jumps)
        return tracker, robot, link, state_at_end
    finally:
        robot.stop()
        tracker.close()


def _leg_for(k: int) -> LegControl:
    # Detected touchdown k is the climb's touchdown k + 1; even touchdowns are the left leg's.
    return LegControl.from_degrees(*LEGS[Leg.of(wall_of(k + 1))])


def test_open_loop_climb_follows_the_map():
    tracker, robot, _link, state = _run(NO_NOISE, jumps=10)
    assert state == LinkState.RUNNING
    poses = tracker.as_arrays()
    found = detect_touchdowns(poses["time"], poses["x"], poses["y"], ROBOT, _leg_for)
    assert len(found) >= 8
    assert np.all(height_gains(found, ROBOT) > 0), "it climbs"
    schedule = ControlSchedule.of(*(_leg_for(k) for k in range(len(found))))
    model = ROBOT.to_model()
    errors = []
    for k in range(len(found) - 1):
        predicted = iterate_map(model, schedule, found[k].state, 1, first_jump=k).states[-1]
        errors.append(np.max(np.abs(predicted - found[k + 1].state)))
    assert max(errors) < 0.05, f"one-jump prediction errors {np.round(errors, 4)} (1 mm tracker noise)"
    assert tracker.stats.loss < 0.1 and robot.climber.frames_sent > 100


def _one_jump_errors(found, model, leg_for) -> np.ndarray:
    schedule = ControlSchedule.of(*(leg_for(k) for k in range(len(found))))
    errors = []
    for k in range(len(found) - 1):
        predicted = iterate_map(model, schedule, found[k].state, 1, first_jump=k).states[-1]
        errors.append(np.max(np.abs(predicted - found[k + 1].state)))
    return np.array(errors)


def test_the_robots_true_physics_and_leg_offsets_are_what_it_climbs_with():
    # The truth a calibration is tested against (parkour robot-sim --alpha ... --psi0-offset-deg L R):
    # the map predicts the tracked touchdowns from the truth, and not from the paper's model.
    truth = replace(ROBOT.to_model(), alpha=85.0, c_zeta=1.4)
    robot = PhysicalParams.from_model(truth, mass=ROBOT.mass, leg_length=ROBOT.leg_length, gravity=ROBOT.gravity)
    offsets = LegOffsets(psi0_offset_deg=(0.8, -0.6), zeta0_offset=(0.004, -0.003))
    tracker, _robot, _link, _state = _run(
        NO_NOISE, jumps=8, robot=robot, leg_offsets=offsets, tracker_noise=0.0, drop_rate=0.0
    )
    poses = tracker.as_arrays()
    found = detect_touchdowns(poses["time"], poses["x"], poses["y"], ROBOT, _leg_for)
    assert len(found) >= 6

    def realised(k: int) -> LegControl:
        return offsets.applied(_leg_for(k), right_leg=found[k].wall == Wall.RIGHT)

    with_truth = _one_jump_errors(found, truth, realised)
    with_paper = _one_jump_errors(found, ROBOT.to_model(), _leg_for)
    assert with_truth.max() < 0.01, f"the truth predicts its touchdowns: errors {np.round(with_truth, 4)}"
    assert with_paper.min() > 3 * with_truth.max(), f"the paper's model does not: {np.round(with_paper, 4)}"


def test_noisy_robot_eventually_falls_and_says_so():
    noise = NoiseModel(psi0_deg=3.0, zeta0=0.02, velocity=0.05, pitch_drift_deg=3.0)
    _tracker, robot, link, state = _run(noise, jumps=400, speed=20.0, seed=3)
    assert state == LinkState.DISARMED, "a failing jump disarms the robot"
    assert link.telemetry.faults & Fault.FELL and robot.climber.jumps < 400
    assert robot.climber.end is not None, f"it says why: {robot.climber.end}"


def test_a_descending_robot_stops_at_the_floor():
    """Beyond the in-place zeta0 (0.964 at 30°) the gait descends: the body reaches the floor and
    the robot reports a fall, instead of the model descending for ever."""
    descending = {Leg.LEFT: (30.0, 0.98), Leg.RIGHT: (30.0, 0.98)}
    tracker, robot, link, state = _run(NO_NOISE, jumps=200, speed=20.0, legs=descending)
    assert state == LinkState.DISARMED and link.telemetry.faults & Fault.FELL
    assert robot.climber.jumps < 200 and robot.climber.end is ClimbEnd.FLOOR
    assert tracker.as_arrays()["y"].min() > FLOOR - 0.01, "nothing is tracked below the floor (1 mm noise)"


def test_in_a_world_it_climbs_the_worlds_sides_and_slips_where_they_give_no_grip():
    """A chute with no grip above 0.2 m (parkour robot-sim --world FILE): the robot climbs to it,
    slips there, and says so; every tracked pose stays inside the sides."""
    grip = np.array([[-1.21, 0.0], [-1.21, 0.2 / ROBOT.leg_length], [-1.21, 9.0]])
    greasy = World(Side(grip, np.array([np.nan, 0.0])), Side(grip * [-1, 1], np.array([np.nan, 0.0])), "greasy")
    tracker, robot, link, state = _run(NO_NOISE, jumps=40, speed=20.0, world=greasy, tracker_noise=0.0)
    assert state == LinkState.DISARMED and link.telemetry.faults & Fault.FELL
    assert robot.climber.end is Failure.SLIP and robot.climber.jumps < 10
    poses = tracker.as_arrays()
    assert np.abs(poses["x"]).max() < 1.21 * ROBOT.leg_length, "inside the chute"
