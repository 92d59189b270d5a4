"""The virtual robot's body: the SLIP model climbing in real time, seen by a 100 Hz tracker.

While the firmware says ``running``, jump after jump is simulated with the legs' current
controls plus the imperfections the paper reports (:class:`sim_core.noise.NoiseModel`: L/R
asymmetry, control noise, pitch drift offsetting the leg angles, noisy section states), and the
body's path is streamed as tracker datagrams in real time (or ``speed`` times faster), with
position noise and dropped frames. A failing jump (slip, no flight, ...) ends the climb: the
robot falls and reports it. So does reaching the chute's floor (the body below the first foot's
height, ``FLOOR``): the model alone would let a descending gait fall forever.
"""

from __future__ import annotations

import math
import socket
import threading
import time
from collections.abc import Callable

import numpy as np

from backend.robot.messages import Leg
from backend.robot.tracker import Pose, encode_datagram
from sim_core import ControlSchedule, LegControl, PhysicalParams, find_fixed_point, get_preset, simulate_trajectory
from sim_core.fixed_points import FixedPointNotFound
from sim_core.noise import NoiseModel
from sim_core.trajectory import STANCE
from sim_core.validation import check_range

FRAME_RATE = 100.0  # [Hz] the FLEX V100's
FLOOR = 0.0  # [m] the chute's floor: where the first foot touches
LAUNCH_GUESS = (-0.93, -0.2)


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
        tracker_noise: float = 0.001,
        drop_rate: float = 0.02,
        speed: float = 1.0,
        seed: int = 0,
    ):
        self.legs, self.running, self.fell = legs, running, fell
        self.tracker_to = tracker_to
        self.robot = robot or get_preset("paper")
        self.model = self.robot.to_model()
        self.noise = noise or NoiseModel()
        self.tracker_noise = check_range("tracker_noise", tracker_noise, 0.0, 0.1, low_open=False)
        self.drop_rate = check_range("drop_rate", drop_rate, 0.0, 1.0, low_open=False)
        self.speed = check_range("speed", speed, 0.0, 100.0)
        self.rng = np.random.default_rng(seed)
        self.frames_sent = 0
        self.frames_dropped = 0
        self.jumps = 0
        self._socket = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._loop, name="virtual-climber", daemon=True)

    def start(self) -> Climber:
        self._thread.start()
        return self

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

    def _controls(self, jump: int, pitch: float) -> LegControl:
        """Jump ``jump``'s leg with the robot's imperfections (noise.py's conventions)."""
        leg = Leg.LEFT if jump % 2 == 0 else Leg.RIGHT
        psi0_deg, zeta0 = self.legs()[leg]
        noise = self.noise
        psi0 = math.radians(psi0_deg) + (pitch if leg == Leg.LEFT else -pitch)
        if leg == Leg.RIGHT:
            psi0 += math.radians(noise.asymmetry_psi0_deg)
            zeta0 += noise.asymmetry_zeta0
        psi0 += self.rng.normal(0.0, math.radians(noise.psi0_deg)) if noise.psi0_deg else 0.0
        zeta0 += self.rng.normal(0.0, noise.zeta0) if noise.zeta0 else 0.0
        return LegControl(min(max(psi0, 1e-3), math.radians(89.0)), min(max(zeta0, 0.05), 0.995))

    def _climb(self) -> None:
        """One climb from launch until stopped or fallen."""
        pitch = 0.0
        this = self._controls(0, pitch)
        try:
            state = find_fixed_point(self.model, ControlSchedule.of(this), 1, LAUNCH_GUESS).state
        except FixedPointNotFound:
            state = np.array(LAUNCH_GUESS)
        height = this.zeta0 * math.sin(this.psi0)
        clock = 0.0  # robot time [s] of the current touchdown
        started = time.monotonic()
        jump = 0
        while self.running() and not self._stop.is_set():
            # Stance does not depend on the next leg: stream it first, then read the next leg's
            # controls at lift-off — as the real robot positions that leg during this stance.
            rate = FRAME_RATE * self.robot.scales.time
            side = 1.0 if jump % 2 == 0 else -1.0  # the wall frame alternates: odd jumps start on the right
            stance = simulate_trajectory(
                self.model, ControlSchedule.of(this, this), state, 1, sample_rate=rate, start_height=height
            ).to_si(self.robot)
            in_stance = stance.phase == STANCE
            if self._stream_to_floor(
                clock + stance.time[in_stance], side * stance.x[in_stance], stance.y[in_stance], pitch, started
            ):
                return
            if not self.running() or self._stop.is_set():
                return
            drift = math.radians(self.noise.pitch_drift_deg)
            next_pitch = pitch + (self.rng.normal(0.0, drift) if drift else 0.0)
            following = self._controls(jump + 1, next_pitch)
            path = simulate_trajectory(
                self.model, ControlSchedule.of(this, following), state, 1, sample_rate=rate, start_height=height
            )
            si = path.to_si(self.robot)
            in_flight = si.phase != STANCE
            if self._stream_to_floor(
                clock + si.time[in_flight], side * si.x[in_flight], si.y[in_flight], pitch, started
            ):
                return
            if path.failure is not None:
                self.fell()
                return
            clock += si.touchdown_times[-1]
            state = path.section_states[-1] + (
                self.rng.normal(0.0, self.noise.velocity, 2) if self.noise.velocity else 0.0
            )
            height = float(si.y[-1]) / self.robot.leg_length
            this, pitch = following, next_pitch
            jump += 1
            self.jumps += 1

    def _stream_to_floor(self, times, xs, ys, pitch: float, started: float) -> bool:
        """Stream the samples above the floor; True (and the robot has fallen) if it was reached."""
        below = np.flatnonzero(ys < FLOOR)
        if below.size == 0:
            self._stream(times, xs, ys, pitch, started)
            return False
        end = below[0]
        self._stream(times[:end], xs[:end], ys[:end], pitch, started)
        if self.running():
            self.fell()
        return True

    def _stream(self, times, xs, ys, pitch: float, started: float) -> None:
        for t, x, y in zip(times, xs, ys, strict=True):
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
            self._socket.sendto(encode_datagram(self.frames_sent, noisy), self.tracker_to)
