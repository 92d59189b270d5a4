"""Tracked climbs without sockets: a robot with known true physics climbs in sim_core's sequencer
(as the virtual robot does), a 100 Hz tracker sees it with noise, and the PC's touchdown detector
reads it with the paper's model — the data a calibration test fits, seconds faster than real time.
:func:`store_tracked_run` files one as a robot run the way a live run is filed (its journal folded)."""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from backend.robot.touchdown import Touchdown, detect_touchdowns
from sim_core import ControlSchedule, LegControl, PhysicalParams, gait_of, get_preset
from sim_core.climb.records import ClimbSetup
from sim_core.climb.sequencer import simulate_climb
from sim_core.model.controls import LegOffsets
from sim_core.model.errors import FixedPointNotFound
from sim_core.model.noise import NoiseModel
from sim_core.model.noise_rules import NoiseSampler
from sim_core.model.presets import START_GUESS
from sim_core.model.walls import Wall

PAPER = get_preset("paper")
FRAME_RATE = 100.0  # [Hz]
# Gaits the test runs climb (psi0_deg, zeta0) left and right: varied, so the fit can tell parameters apart.
VARIED_LEGS = (((30.0, 0.90), (30.0, 0.90)), ((30.0, 0.87), (30.0, 0.90)), ((33.0, 0.92), (28.0, 0.88)),
               ((27.0, 0.89), (32.0, 0.91)))  # fmt: skip


@dataclass(frozen=True)
class Truth:
    """What the robot really is: the physics and the legs' servo offsets."""

    robot: PhysicalParams
    offsets: LegOffsets

    @classmethod
    def of(cls, *, alpha: float, c_zeta: float, c_psi: float, psi0_offset_deg, zeta0_offset) -> Truth:
        model = replace(PAPER.to_model(), alpha=alpha, c_zeta=c_zeta, c_psi=c_psi)
        robot = PhysicalParams.from_model(model, mass=PAPER.mass, leg_length=PAPER.leg_length, gravity=PAPER.gravity)
        return cls(robot, LegOffsets(psi0_offset_deg=tuple(psi0_offset_deg), zeta0_offset=tuple(zeta0_offset)))


@dataclass(frozen=True)
class TrackedClimb:
    frames: dict[str, np.ndarray]  # time [s], x, y [m], pitch [rad]: the tracker's
    touchdowns: list[Touchdown]  # as the PC detects them, with the paper's model
    controls: list[tuple[float, float]]  # commanded (psi0_deg, zeta0) of each detected touchdown


def tracked_climb(truth: Truth, legs, *, jumps: int, noise: NoiseModel, rng, tracker_noise=0.001) -> TrackedClimb:
    """A climb of up to ``jumps`` jumps commanded ``legs`` ((psi0_deg, zeta0) left, right)."""
    commanded = {Wall.LEFT: LegControl.from_degrees(*legs[0]), Wall.RIGHT: LegControl.from_degrees(*legs[1])}
    setup = ClimbSetup(truth.robot, sample_rate=FRAME_RATE * truth.robot.scales.time)
    realised = {wall: truth.offsets.applied(leg, right_leg=wall == Wall.RIGHT) for wall, leg in commanded.items()}
    try:  # launched as the virtual robot launches (backend/robot/climber.py)
        state = gait_of(truth.robot.to_model(), ControlSchedule.of(realised[Wall.LEFT]), guess=START_GUESS).state
    except FixedPointNotFound:
        state = np.array(START_GUESS)
    done = simulate_climb(
        setup,
        realised.__getitem__,
        state,
        jumps,
        NoiseSampler(noise, rng),
    )
    time = np.concatenate([jump.samples.time for jump in done])
    x = np.concatenate([jump.samples.x for jump in done]) + rng.normal(0.0, tracker_noise, time.size)
    y = np.concatenate([jump.samples.y for jump in done]) + rng.normal(0.0, tracker_noise, time.size)
    # Seen as the virtual robot reports it: a stance with its jump's pitch, the flight after the lift-off's step.
    pitch = np.concatenate([np.where(np.arange(len(jump.samples)) < jump.liftoff, jump.start.pitch, jump.next.pitch)
                            for jump in done])  # fmt: skip

    def leg_for(k: int) -> LegControl:  # detected touchdown k is the climb's k + 1
        return commanded[Wall.RIGHT if k % 2 == 0 else Wall.LEFT]

    found = detect_touchdowns(time, x, y, PAPER, leg_for, pitch)
    controls = [(commanded[td.wall].psi0_deg, commanded[td.wall].zeta0) for td in found]
    return TrackedClimb({"time": time, "x": x, "y": y, "pitch": pitch}, found, controls)


def store_tracked_run(session, climb: TrackedClimb, legs, *, fell: bool = False) -> int:
    """``climb`` filed as a finished robot run (opened, one journal entry, folded); its id. ``fell``:
    it ended as a fall does (the firmware's FELL fault in its telemetry, the robot disarmed)."""
    from backend.robot.live_run import CLEAN_ENDINGS
    from backend.robot.messages import Fault
    from backend.schemas import LegIn, RobotRunCreate
    from tests.robot_runs import store_journaled_run

    request = RobotRunCreate(controls=[LegIn(psi0_deg=p, zeta0=z) for p, z in legs], jumps=len(climb.touchdowns) + 1)
    entry = {
        "frames": {name: column.tolist() for name, column in climb.frames.items()},
        "touchdowns": [{"touchdown": td.to_dict(), "control": list(control)}
                       for td, control in zip(climb.touchdowns, climb.controls, strict=True)],
        "commands": [], "telemetry": [{"seq": 1, "faults": int(Fault.FELL) if fell else 0}], "transitions": [],
        "tracker": {"dropped": 0, "loss": 0.0},
    }  # fmt: skip
    ending = "robot disarmed (fell or timed out)" if fell else CLEAN_ENDINGS[0]
    return store_journaled_run(session, request, lambda _start: [entry], end_reason=ending)


def store_varied_runs(session, truth: Truth, *, noise: NoiseModel, jumps: int = 40, seed: int = 3) -> list[int]:
    """One stored robot run per gait of :data:`VARIED_LEGS`, the robot being ``truth``; their ids."""
    rng = np.random.default_rng(seed)
    return [
        store_tracked_run(session, tracked_climb(truth, legs, jumps=jumps, noise=noise, rng=rng), legs)
        for legs in VARIED_LEGS
    ]
