"""The virtual robot's body: the SLIP model climbing in real time, seen by a 100 Hz tracker.

A thin, threaded driver of :mod:`sim_core.climb.sequencer` (the climb sequencer the 3D view runs too).
While the firmware says ``running``, jump after jump is simulated with the legs' current
controls plus the imperfections the paper reports: each leg's servo offsets (``leg_offsets``, the
truth a calibration should recover) and :mod:`sim_core.model.noise` (control noise, pitch drift
offsetting the leg angles, noisy section states), and the body's path is
streamed as tracker datagrams in real time (or ``speed`` times faster), with position noise and
dropped frames, as PKT1 datagrams or, with ``tracker_protocol="natnet"``, as the camera software's
NatNet frames (:mod:`backend.robot.natnet_frame`: one rigid body, the table plane its x–y plane, the
pitch its rotation about z). Each stance is streamed before the next leg is read, as the real robot positions
that leg during the stance. The climb ends when a jump fails (slip, no flight, ...) or the body
reaches the chute's floor (:data:`sim_core.climb.records.FLOOR`, where the first foot touches): the
robot falls and reports it, and :attr:`Climber.end` says why.
"""

from __future__ import annotations

import socket
import threading
import time
from collections.abc import Callable

import numpy as np

from backend.robot.messages import Leg
from backend.robot.natnet import parse_version
from backend.robot.natnet_frame import RigidBody, encode_frame, quaternion_about_z
from backend.robot.tracker import Pose, encode_datagram
from sim_core import ControlSchedule, LegControl, PhysicalParams, gait_of, get_preset
from sim_core.climb import sequencer as climb
from sim_core.climb.records import ClimbSetup, End, Samples
from sim_core.model.controls import NO_OFFSETS, LegOffsets
from sim_core.model.errors import FixedPointNotFound, ParameterError
from sim_core.model.noise import NoiseModel
from sim_core.model.noise_rules import NoiseSampler
from sim_core.model.presets import START_GUESS
from sim_core.model.validation import check_range
from sim_core.model.walls import Wall
from sim_core.world.world import World

FRAME_RATE = 100.0  # [Hz] the FLEX V100's


class Climber:
    def __init__(
        self,
        legs: Callable[[], dict[Leg, tuple[float, float]]],
        running: Callable[[], bool],
        fell: Callable[[], None],
        tracker_to: tuple[str, int],
        *,
        robot: PhysicalParams | None = None,
        noise: NoiseModel | None = None,
        leg_offsets: LegOffsets = NO_OFFSETS,
        tracker_noise: float = 0.001,
        drop_rate: float = 0.02,
        speed: float = 1.0,
        seed: int = 0,
        tracker_protocol: str = "pkt1",
        natnet_version: str = "3.1",
        natnet_rigid_body_id: int = 1,
        world: World | None = None,
    ):
        self.legs, self.running, self.fell = legs, running, fell
        self.world = world  # the chute it climbs (docs/model.md §8); None: parallel walls
        self.tracker_to = tracker_to
        self.robot = robot or get_preset("paper")
        self.model = self.robot.to_model()
        self.noise = noise or NoiseModel()
        self.leg_offsets = leg_offsets
        self.tracker_noise = check_range("tracker_noise", tracker_noise, 0.0, 0.1, low_open=False)
        self.drop_rate = check_range("drop_rate", drop_rate, 0.0, 1.0, low_open=False)
        self.speed = check_range("speed", speed, 0.0, 100.0)
        if tracker_protocol not in ("pkt1", "natnet"):
            raise ParameterError("tracker_protocol", f"must be pkt1 or natnet, got {tracker_protocol!r}")
        self.tracker_protocol = tracker_protocol
        self.natnet_version = parse_version(natnet_version)
        self.natnet_rigid_body_id = int(
            check_range("natnet_rigid_body_id", natnet_rigid_body_id, 0, 2**31, low_open=False)
        )
        self.seed = seed
        self.climbs = 0  # climbs started: climb k draws from its own streams (_seed_climb)
        self._seed_climb()
        self.end: End | None = None  # why the last climb ended (a failure or the floor)
        self.frames_sent = 0
        self.frames_dropped = 0
        self.jumps = 0
        self._socket = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._loop, name="virtual-climber", daemon=True)

    def start(self) -> Climber:
        self._warm()
        self._thread.start()
        return self

    def _warm(self) -> None:
        """One jump simulated and thrown away, before the robot can be started: a real robot is
        ready when it is switched on, and its first launch must not wait for the kernels to load
        (it did, 0.47 s, which a live run's tracker watch rightly reads as a silent tracker)."""
        setup = ClimbSetup(self.robot, sample_rate=FRAME_RATE * self.robot.scales.time, world=self.world)
        sampler = NoiseSampler(self.noise, np.random.default_rng(0))
        start = self._launch(setup, sampler)
        climb.stance(setup, start)
        climb.jump(setup, start, climb.read_next_leg(start, self._commanded(Wall.RIGHT), sampler))

    def stop(self) -> None:
        self._stop.set()
        self._thread.join(5)
        self._socket.close()

    def _loop(self) -> None:
        while not self._stop.is_set():
            if self.running():
                self._climb()
            else:
                self._stop.wait(0.01)

    def _commanded(self, wall: Wall) -> LegControl:
        """What the firmware holds for the leg on ``wall`` now, as its servos realise it (the offsets)."""
        commanded = LegControl.from_degrees(*self.legs()[Leg.of(wall)])
        return self.leg_offsets.applied(commanded, right_leg=wall == Wall.RIGHT)

    def _seed_climb(self) -> None:
        # Streams per climb, so the k-th climb of a seeded robot is the same however long the ones
        # before it ran; and two per climb: its noise does not depend on how many frames were streamed.
        climb_seed, tracker_seed = np.random.SeedSequence([self.seed, self.climbs]).spawn(2)
        self._climb_rng = np.random.default_rng(climb_seed)
        self.rng = np.random.default_rng(tracker_seed)  # tracker noise and dropped frames

    def _climb(self) -> None:
        """One climb from launch until stopped, failed or at the floor."""
        self._seed_climb()
        self.climbs += 1
        setup = ClimbSetup(self.robot, sample_rate=FRAME_RATE * self.robot.scales.time, world=self.world)
        sampler = NoiseSampler(self.noise, self._climb_rng)
        start = self._launch(setup, sampler)
        started = time.monotonic()
        self.end = None
        while self._active():
            stance = climb.stance(setup, start)
            if not self._streamed(stance.samples, stance.end, start.pitch, started):
                return
            # Read at lift-off: the robot positioned this leg during the stance just streamed.
            next_leg = climb.read_next_leg(start, self._commanded(start.wall.other), sampler)
            jump = climb.jump(setup, start, next_leg)
            # The pitch stepped at lift-off: the flight is seen with the pitch the next leg reaches at.
            if not self._streamed(jump.flight, jump.end, next_leg.pitch, started):
                return
            start = climb.touchdown_after(setup, jump, sampler)
            self.jumps += 1

    def _launch(self, setup: ClimbSetup, sampler: NoiseSampler):
        """The climb's first stance, from the gait of the left leg's controls (or a standard start)."""
        first = self._commanded(Wall.LEFT)
        try:
            state = gait_of(self.model, ControlSchedule.of(first), guess=START_GUESS).state
        except FixedPointNotFound:  # launch anyway: the firmware's controls need not have a gait
            state = np.array(START_GUESS)
        return climb.launch(setup, first, state, sampler)

    def _streamed(self, samples, end, pitch: float, started: float) -> bool:
        """Stream ``samples``; whether the climb goes on (False once stopped, or at ``end``, a fall)."""
        self._stream(samples, pitch, started)
        if not self._active():
            return False
        if end is not None:
            self._fall(end)
            return False
        return True

    def _active(self) -> bool:
        return self.running() and not self._stop.is_set()

    def _fall(self, end: End) -> None:
        self.end = end
        self.fell()

    def _stream(self, samples: Samples, pitch: float, started: float) -> None:
        for t, x, y in zip(samples.time, samples.x, samples.y, strict=True):
            delay = started + t / self.speed - time.monotonic()
            if delay > 0 and self._stop.wait(delay):
                return
            if not self.running():
                return
            self.frames_sent += 1
            if self.rng.random() < self.drop_rate:
                self.frames_dropped += 1
                continue
            noisy = Pose(
                float(t),
                float(x) + self.rng.normal(0, self.tracker_noise),
                float(y) + self.rng.normal(0, self.tracker_noise),
                pitch,
            )
            self._socket.sendto(self._datagram(self.frames_sent, noisy), self.tracker_to)

    def _datagram(self, frame: int, pose: Pose) -> bytes:
        """What the camera sends for ``pose``: a PKT1 datagram, or a NatNet frame holding the body."""
        if self.tracker_protocol == "pkt1":
            return encode_datagram(frame, pose)
        body = RigidBody(self.natnet_rigid_body_id, (pose.x, pose.y, 0.0), quaternion_about_z(pose.pitch))
        return encode_frame(frame, pose.time, body, self.natnet_version)
