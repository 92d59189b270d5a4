"""Closed-loop climbs without sockets or real time: a robot of known true physics (its servo
offsets, the noise of docs/model.md §5.1) climbs in sim_core's sequencer as the virtual robot does,
a 100 Hz tracker sees it with noise and dropped frames, and the PC's side runs as a live run does
(backend/robot/live_run.py): touchdowns scanned from the poses so far with the PC's model,
each one's height, pitch and section state through the law (backend/robot/live_law.py) to the
leg of the next touchdown, read at lift-off. What a live run does in real time, in a fraction of
a second a climb, so a study of ten 300-jump runs per controller is a minute, not an hour.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from backend.robot.live_law import LiveLaw, pitch_at
from backend.robot.touchdown import Touchdown, scan_touchdowns
from sim_core import ControlSchedule, LegControl, PhysicalParams, gait_of
from sim_core.climb import sequencer as climb
from sim_core.climb.records import ClimbSetup
from sim_core.model.errors import FixedPointNotFound
from sim_core.model.noise import NoiseModel
from sim_core.model.noise_rules import NoiseSampler
from sim_core.model.presets import START_GUESS
from sim_core.model.walls import Wall, wall_of
from tests.tracked_climbs import FRAME_RATE, Truth


@dataclass(frozen=True)
class ClosedClimb:
    touchdowns: list[Touchdown]  # as the PC detected them
    fell: bool  # ended by a failing jump or the floor before its touchdowns were in


def closed_climb(
    truth: Truth,
    pc_robot: PhysicalParams,
    legs: tuple[LegControl, LegControl],
    law: LiveLaw | None,
    *,
    touchdowns: int,
    noise: NoiseModel,
    rng: np.random.Generator,
    tracker_noise: float = 0.001,
    drop_rate: float = 0.02,
) -> ClosedClimb:
    """Climb until ``touchdowns`` are detected or the robot falls; ``legs`` the start controls (left,
    right), ``law`` the closed loop (None: open loop); ``pc_robot`` what the PC believes (the
    touchdown detector's model, as the service's preset)."""
    commanded = {Wall.LEFT: legs[0], Wall.RIGHT: legs[1]}

    def realised(wall: Wall) -> LegControl:
        return truth.offsets.applied(commanded[wall], right_leg=wall == Wall.RIGHT)

    setup = ClimbSetup(truth.robot, sample_rate=FRAME_RATE * truth.robot.scales.time)
    sampler = NoiseSampler(noise, rng)
    try:  # launched as the virtual robot launches (backend/robot/climber.py)
        state = gait_of(truth.robot.to_model(), ControlSchedule.of(realised(Wall.LEFT)), guess=START_GUESS).state
    except FixedPointNotFound:
        state = np.array(START_GUESS)
    start = climb.launch(setup, realised(Wall.LEFT), state, sampler)
    frames: dict[str, list[np.ndarray]] = {"time": [], "x": [], "y": [], "pitch": []}
    found: list[Touchdown] = []
    made_with: list[LegControl] = []
    scan_from = 1

    def seen(samples, pitch: float) -> None:
        kept = rng.random(len(samples.time)) >= drop_rate
        frames["time"].append(samples.time[kept])
        frames["x"].append(samples.x[kept] + rng.normal(0.0, tracker_noise, kept.sum()))
        frames["y"].append(samples.y[kept] + rng.normal(0.0, tracker_noise, kept.sum()))
        frames["pitch"].append(np.full(kept.sum(), pitch))

    def leg_for(k: int) -> LegControl:  # detected touchdown k is the climb's k + 1, made with its leg then
        return made_with[k] if k < len(made_with) else commanded[wall_of(k + 1)]

    while True:
        stance = climb.stance(setup, start)
        seen(stance.samples, start.pitch)
        if stance.end is not None:
            return ClosedClimb(found, True)
        arrays = {name: np.concatenate(parts) for name, parts in frames.items()}
        scan = scan_touchdowns(arrays["time"], arrays["x"], arrays["y"], pc_robot, leg_for, arrays["pitch"],
                               start=scan_from, first_index=len(found))  # fmt: skip
        scan_from = scan.resume
        for touchdown in scan.touchdowns:
            made_with.append(leg_for(touchdown.index))
            found.append(touchdown)
            if law is not None:
                wall = wall_of(touchdown.index + 2)
                pitch = pitch_at(arrays["time"], arrays["pitch"], touchdown.time)
                commanded[wall], _ = law.command(touchdown, pitch, commanded[wall].psi0)
        if len(found) >= touchdowns:
            return ClosedClimb(found[:touchdowns], False)
        # Read at lift-off: the robot positioned this leg during the stance just seen.
        next_leg = climb.read_next_leg(start, realised(start.wall.other), sampler)
        jump = climb.jump(setup, start, next_leg)
        seen(jump.flight, next_leg.pitch)
        if jump.end is not None:
            return ClosedClimb(found, True)
        start = climb.touchdown_after(setup, jump, sampler)


def held(climb_: ClosedClimb, target_m: float, *, last: int = 100, within_m: float = 0.02) -> bool:
    """Whether a climb held ``target_m``: it did not fall, and its last ``last`` touchdowns are
    within ``within_m`` of the target on average."""
    if climb_.fell:
        return False
    heights = np.array([td.body_height for td in climb_.touchdowns[-last:]])
    return bool(np.mean(np.abs(heights - target_m)) < within_m) and math.isfinite(heights.sum())
