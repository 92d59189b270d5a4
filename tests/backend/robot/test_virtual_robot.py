"""The virtual robot: its radio answers as an XBee does, and in an open-loop run it climbs and its
tracked touchdowns follow the map."""

import socket
import time
from dataclasses import replace

import numpy as np

from backend.robot.link import LinkState
from backend.robot.messages import Ack, Command, Fault, Kind, Leg, RobotState, decode, encode
from backend.robot.touchdown import detect_touchdowns, height_gains
from backend.robot.tracker import UdpPoseSource
from backend.robot.virtual import VirtualRobot
from backend.robot.xbee import (
    ROBOT_ADDRESS,
    TX_STATUS,
    FrameParser,
    encode_frame,
    parse_rx_packet,
    parse_tx_status,
    tx_request,
)
from sim_core import ControlSchedule, LegControl, PhysicalParams, get_preset, iterate_map
from sim_core.climb import FLOOR, ClimbEnd
from sim_core.controls import LegOffsets
from sim_core.noise import NO_NOISE, NoiseModel
from sim_core.walls import Wall, wall_of
from tests.robot_rig import climb_open_loop

LEGS = {Leg.LEFT: (30.0, 0.87), Leg.RIGHT: (30.0, 0.9)}
ROBOT = get_preset("paper")
FOREIGN = 0x0013A200DEADBEEF  # no such radio in the virtual robot's network


def _request(message, frame_id: int, destination64: int = ROBOT_ADDRESS) -> bytes:
    return encode_frame(tx_request(encode(message), frame_id=frame_id, destination64=destination64))


def _answers(connection: socket.socket, until_status: int, timeout: float = 3.0) -> list:
    """Transmit Statuses and the robot's messages (no TELEMETRY), in arrival order, up to the status
    for frame ``until_status``."""
    parser, out = FrameParser(), []
    deadline = time.monotonic() + timeout
    while not any(getattr(item, "frame_id", None) == until_status for item in out):
        assert time.monotonic() < deadline, f"no transmit status for frame {until_status}: {out}"
        for data in parser.feed(connection.recv(4096)):
            if data[0] == TX_STATUS:
                out.append(parse_tx_status(data))
            elif isinstance(message := decode(parse_rx_packet(data).payload), Ack):
                out.append(message)
    return out


def test_the_radio_answers_transmit_status_as_an_xbee_does():
    robot = VirtualRobot().start()
    try:
        with socket.create_connection(robot.address, timeout=3.0) as connection:
            connection.sendall(
                _request(Command(1, Kind.ARM), frame_id=7)
                + _request(Command(2, Kind.HEARTBEAT), frame_id=0)  # frame id 0: no status wanted
                + _request(Command(3, Kind.ESTOP), frame_id=8, destination64=FOREIGN)
                + _request(Command(4, Kind.HEARTBEAT), frame_id=9)
            )
            answers = _answers(connection, until_status=9)
    finally:
        robot.stop()
    statuses = [(a.frame_id, a.delivery, a.retries) for a in answers if not isinstance(a, Ack)]
    assert statuses == [(7, 0x00, 0), (8, 0x24, 0), (9, 0x00, 0)], "delivered, no retries; no radio at FOREIGN"
    assert not isinstance(answers[0], Ack) and isinstance(answers[1], Ack), "the status comes before the reply"
    assert [a.acked for a in answers if isinstance(a, Ack)] == [1], "HEARTBEAT has no ack, the ESTOP never arrived"
    assert robot.firmware.state == RobotState.ARMED


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
