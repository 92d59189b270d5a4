"""Closed-loop height control: a PID closed once per jump on the touchdown height (paper Fig. 12).

At each touchdown (the Poincaré section) the body height is measured; the height error
``e = target - height`` sets the leg length of the *next* touchdown, so the loop acts with
one jump of delay, as on the robot:

    zeta0_next = clamp(zeta0_hover - (kp e + ki sum(e) + kd (e - e_prev)), zeta0_min, zeta0_max)

``zeta0_hover`` is the feed-forward: the zeta0 of jumping in place
(:func:`sim_core.basins.sweep.find_in_place_zeta0`); more retraction (smaller zeta0) climbs. The
integrator stops accumulating while the command is saturated in the direction the error
pushes (conditional integration, a standard anti-windup). Disturbances are those of
:mod:`sim_core.model.noise`, drawn in the compiled loop from one seed.

Heights are body heights at touchdown, foot height plus ``zeta0 sin psi0`` [l0]; the first
foot touches at height 0.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from sim_core._jit import kernel
from sim_core.control.height_controller import HeightController
from sim_core.model.controls import ControlSchedule, LegControl
from sim_core.model.failures import FLOOR, FLOOR_HEIGHT, OK, Failure
from sim_core.model.integrate import STATE_SIZE
from sim_core.model.noise import NO_NOISE, NoiseModel
from sim_core.model.noise_rules import disturbed_state, perturbed_controls, pitch_step, seed_trial
from sim_core.model.params import ModelParams
from sim_core.model.poincare import check_jumps, check_section_state
from sim_core.model.stride import jump
from sim_core.model.validation import check_range

SETTLING_BAND = 0.02  # |error| within 2% of the climb to the target counts as settled


@dataclass(frozen=True)
class ClosedLoopRun:
    """A closed-loop climb; arrays have one entry per touchdown reached (jumps completed + 1).

    Attributes:
        time: touchdown times [sqrt(l0/g)], starting at 0.
        height: body height at each touchdown [l0].
        zeta0: the leg length used at each touchdown.
        states: section states, shape (n, 2).
        failure: the failure that ended the run early, or None.
    """

    controller: HeightController
    psi0: float
    time: np.ndarray
    height: np.ndarray
    zeta0: np.ndarray
    states: np.ndarray
    failure: Failure | None

    @property
    def error(self) -> np.ndarray:
        return self.controller.target - self.height

    def rise_time(self) -> float:
        """Time from 10% to 90% of the climb from the first touchdown to the target [sqrt(l0/g)]."""
        start = self.height[0]
        span = self.controller.target - start
        progress = (self.height - start) / span
        reach10 = np.flatnonzero(progress >= 0.1)
        reach90 = np.flatnonzero(progress >= 0.9)
        if reach10.size == 0 or reach90.size == 0:
            return math.nan
        return float(self.time[reach90[0]] - self.time[reach10[0]])

    def overshoot(self) -> float:
        """Largest excursion past the target as a fraction of the climb (0 if none)."""
        span = self.controller.target - self.height[0]
        return max(0.0, float(np.max((self.height - self.controller.target) * np.sign(span))) / abs(span))

    def settling_jump(self) -> int | None:
        """First touchdown after which the error stays within the settling band, or None."""
        band = SETTLING_BAND * abs(self.controller.target - self.height[0])
        outside = np.flatnonzero(np.abs(self.error) > band)
        if outside.size == 0:
            return 0
        first_inside = int(outside[-1]) + 1
        return first_inside if first_inside < self.height.size else None

    def steady_error(self) -> float:
        """Mean |error| over the last quarter of the run [l0]."""
        tail = self.error[-max(1, self.error.size // 4) :]
        return float(np.mean(np.abs(tail)))

    def to_dict(self) -> dict:
        """The ``parkour pid --json`` contract (nondimensional; the CLI adds SI)."""
        controller = self.controller
        settled = self.settling_jump()
        return {
            "target": controller.target,
            "gains": {"kp": controller.kp, "ki": controller.ki, "kd": controller.kd},
            "zeta0_hover": controller.zeta0_hover,
            "zeta0_range": [controller.zeta0_min, controller.zeta0_max],
            "psi0_deg": round(math.degrees(self.psi0), 9),
            "jumps": int(self.height.size - 1),
            "failure": None if self.failure is None else self.failure.code,
            "rise_time": self.rise_time(),
            "overshoot": self.overshoot(),
            "settling_jump": settled,
            "settling_time": None if settled is None else float(self.time[settled]),
            "steady_error": self.steady_error(),
            "time": self.time.tolist(),
            "height": self.height.tolist(),
            "zeta0": self.zeta0.tolist(),
        }


def closed_loop_climb(
    model: ModelParams,
    controller: HeightController,
    psi0: float,
    start,
    jumps: int,
    *,
    start_zeta0: float | None = None,
    noise: NoiseModel = NO_NOISE,
    seed: int = 0,
) -> ClosedLoopRun:
    """Climb under the height controller from section state ``start`` for ``jumps`` jumps.

    ``start_zeta0`` is the leg length of the first touchdown (default: ``zeta0_hover``); the
    controller's first command sets the second.
    """
    LegControl(psi0, controller.zeta0_hover)  # validates psi0
    state = check_section_state(start)
    jumps = check_jumps(jumps)
    check_range("seed", seed, 0, 2**32, low_open=False, high_open=True)
    first_zeta0 = controller.zeta0_hover if start_zeta0 is None else start_zeta0
    check_range("start_zeta0", first_zeta0, 0.0, 1.0)
    schedule = ControlSchedule.of(LegControl(psi0, first_zeta0)).as_array()
    time = np.full(jumps + 1, math.nan)
    height = np.full(jumps + 1, math.nan)
    zeta0 = np.full(jumps + 1, math.nan)
    states = np.full((jumps + 1, 2), math.nan)
    status, completed = pid_loop(
        state[0],
        state[1],
        schedule,
        first_zeta0,
        controller.target,
        controller.zeta0_hover,
        controller.kp,
        controller.ki,
        controller.kd,
        controller.zeta0_min,
        controller.zeta0_max,
        int(seed),
        noise.record(),
        model.record(),
        time,
        height,
        zeta0,
        states,
    )
    reached = completed + 1
    return ClosedLoopRun(
        controller=controller,
        psi0=psi0,
        time=time[:reached].copy(),
        height=height[:reached].copy(),
        zeta0=zeta0[:reached].copy(),
        states=states[:reached].copy(),
        failure=None if status == OK else Failure(status),
    )


@kernel
def pid_step(error, previous_error, integral, zeta0_hover, kp, ki, kd, zeta0_min, zeta0_max):
    """One PID update: ``(next touchdown's zeta0, new integral)``; ``previous_error`` NaN at the first.

    The one implementation of the height law, compiled, so the simulated loop and a live run on
    the robot (``backend``) use the same arithmetic.
    """
    derivative = 0.0 if math.isnan(previous_error) else error - previous_error
    unclamped = zeta0_hover - (kp * error + ki * (integral + error) + kd * derivative)
    command = min(max(unclamped, zeta0_min), zeta0_max)
    pushing_out = (unclamped < zeta0_min and error > 0.0) or (unclamped > zeta0_max and error < 0.0)
    return command, integral if pushing_out else integral + error


@kernel
def pid_loop(
    xdot,
    ydot,
    schedule,
    first_zeta0,
    target,
    zeta0_hover,
    kp,
    ki,
    kd,
    zeta0_min,
    zeta0_max,
    seed,
    noise,
    model,
    time,
    height,
    zeta0_used,
    states,
):
    """The closed loop, compiled; fills the output arrays per touchdown. Returns ``(status, jumps)``.
    ``noise`` and ``model`` are the records of :class:`NoiseModel` and :class:`ModelParams`."""
    seed_trial(seed)
    no_record = np.empty((0, STATE_SIZE))
    jumps = time.shape[0] - 1
    pitch = 0.0
    psi0, zeta0 = perturbed_controls(schedule, 0, pitch, first_zeta0, noise)
    foot = 0.0
    now = 0.0
    integral = 0.0
    previous_error = math.nan
    for k in range(jumps + 1):
        body = foot + zeta0 * math.sin(psi0)
        time[k] = now
        height[k] = body
        zeta0_used[k] = zeta0
        states[k, 0] = xdot
        states[k, 1] = ydot
        if k == jumps:
            break
        # The PID: this touchdown's error sets the next touchdown's leg length.
        error = target - body
        command, integral = pid_step(error, previous_error, integral, zeta0_hover, kp, ki, kd, zeta0_min, zeta0_max)
        previous_error = error
        next_pitch = pitch_step(pitch, noise)
        next_psi0, next_zeta0 = perturbed_controls(schedule, k + 1, next_pitch, command, noise)
        status, xdot, ydot, rise, stance_time, flight_time, _ = jump(
            xdot, ydot, psi0, zeta0, next_psi0, next_zeta0, model, no_record
        )
        if status != OK:
            return status, k
        xdot, ydot = disturbed_state(xdot, ydot, noise)
        foot += rise
        now += stance_time + flight_time
        pitch, psi0, zeta0 = next_pitch, next_psi0, next_zeta0
        if foot + zeta0 * math.sin(psi0) < FLOOR_HEIGHT:  # lost its height, as in sim_core.control.loop_step
            return FLOOR, k
    return OK, jumps
