"""The controllers closed once per jump, as data: their names and kinds, the leg's range, and each
law's parameters (:class:`Pid`), checked. NumPy only, so the command line and the request schemas
read them without loading the kernels; the compiled law is :mod:`sim_core.control.controllers`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from sim_core.control.height_controller import HeightController
from sim_core.model.validation import ParameterError, check_range

PID, PID_PITCH, LQR, DEADBEAT = 0, 1, 2, 3
KINDS = {"pid": PID, "pid-pitch": PID_PITCH, "lqr": LQR, "deadbeat": DEADBEAT}
# The leg angle's range relative to the body [deg]: the robot's angle servos (backend/robot/limits.py).
PSI0_RANGE_DEG = (10.0, 60.0)
MEMORY_SIZE = 2  # a law's state between touchdowns: the PID's integral and previous error; else the last command


@dataclass(frozen=True)
class Pid:
    """A PID on the touchdown height (``height``: its gains, target and zeta0 range, in l0), the leg
    angle ``psi0_deg`` nominal; with ``pitch_feedback`` the tracked pitch turns the next leg back
    (``pid-pitch``). The commanded angle stays within ``psi0_range_deg`` relative to the body."""

    height: HeightController
    psi0_deg: float
    pitch_feedback: bool = False
    psi0_range_deg: tuple[float, float] = PSI0_RANGE_DEG

    def __post_init__(self) -> None:
        _check_interval("psi0_range_deg", self.psi0_range_deg, 90.0)
        check_range("psi0_deg", self.psi0_deg, *self.psi0_range_deg, low_open=False, high_open=False)

    @property
    def name(self) -> str:
        return "pid-pitch" if self.pitch_feedback else "pid"

    @property
    def target(self) -> float:
        return self.height.target

    def kernel_args(self) -> tuple[int, np.ndarray]:
        """``(kind, parameters)`` for :func:`control_step`."""
        height = self.height
        low, high = (math.radians(value) for value in self.psi0_range_deg)
        parameters = [height.target, height.zeta0_hover, height.kp, height.ki, height.kd, height.zeta0_min,
                      height.zeta0_max, math.radians(self.psi0_deg), low, high, float(self.pitch_feedback)]  # fmt: skip
        return KINDS[self.name], np.array(parameters)


@dataclass(frozen=True)
class Lqr:
    """A discrete LQR on the return map linearised about a gait of jumping in place
    (:func:`sim_core.control.return_map_lqr.design_lqr` computes it from the model). Its state at touchdown
    ``k`` is the section state's deviation from the gait's, the height error (clipped to
    ``±error_clip`` [l0]: a far target is approached at the pace of a near one) and the deviation
    of the controls the robot touched down with (the one jump of delay); its input the next
    touchdown's ``(psi0, zeta0)`` deviation, ``gain`` (2 × 5, row-major: psi0's row, then
    zeta0's). The tracked pitch is fed to the leg angle as in ``pid-pitch``; commands stay within
    ``zeta0_range`` and ``psi0_range_deg`` relative to the body. Angles in the state in rad."""

    target: float  # [l0]
    psi0_deg: float  # the gait's leg angle
    zeta0: float  # the gait's leg length (jumping in place)
    state: tuple[float, float]  # the gait's section state [sqrt(g l0)]
    gain: tuple[float, ...]
    error_clip: float = 0.4  # [l0]
    state_clip: float = 0.15  # [sqrt(g l0)]: each section-state deviation the law acts on, at most
    zeta0_range: tuple[float, float] = (HeightController.zeta0_min, HeightController.zeta0_max)
    psi0_range_deg: tuple[float, float] = PSI0_RANGE_DEG

    def __post_init__(self) -> None:
        check_range("target", self.target, 0.0, 1e4)
        check_range("error_clip", self.error_clip, 0.0, 10.0)
        check_range("state_clip", self.state_clip, 0.0, 10.0)
        _check_interval("zeta0_range", self.zeta0_range, 1.0)
        _check_interval("psi0_range_deg", self.psi0_range_deg, 90.0)
        check_range("psi0_deg", self.psi0_deg, *self.psi0_range_deg, low_open=False, high_open=False)
        if len(self.gain) != 10 or not all(math.isfinite(value) for value in self.gain):
            raise ParameterError("gain", f"must be 10 finite numbers (2 x 5), got {len(self.gain)}")

    name = "lqr"

    def kernel_args(self) -> tuple[int, np.ndarray]:
        """``(kind, parameters)`` for :func:`sim_core.control.controllers.control_step`."""
        psi0_low, psi0_high = (math.radians(value) for value in self.psi0_range_deg)
        parameters = [self.target, math.radians(self.psi0_deg), self.zeta0, *self.state, *self.zeta0_range,
                      psi0_low, psi0_high, self.error_clip, 1.0, *self.gain, self.state_clip]  # fmt: skip
        return LQR, np.array(parameters)


@dataclass(frozen=True)
class Deadbeat:
    """The deadbeat law on a short horizon with a safety guard (:mod:`sim_core.control.deadbeat`; built by
    :func:`sim_core.control.deadbeat.design_deadbeat`): zeta0 chosen each jump by the design model
    (``model``: ``(alpha, d_hat, c_zeta, c_psi, mu)``, :meth:`sim_core.model.params.ModelParams.kernel_args`)
    to climb at most ``climb_per_jump`` [l0] a jump toward ``target`` [l0] over the next two
    touchdowns, keeping the section state near the gait's ``state`` (weight ``q_state``), never a
    command the model predicts fails; the leg angle at ``psi0_deg`` (the pitch fed back as in
    ``pid-pitch``), zeta0 within ``zeta0_range``. ``zeta0`` is the gait's (jumping in place).
    ``guard``: the design model's viability kernel for these controls, which no command leaves."""

    target: float  # [l0]
    psi0_deg: float
    zeta0: float
    state: tuple[float, float]  # the gait's section state [sqrt(g l0)]
    model: tuple[float, float, float, float, float]
    climb_per_jump: float = 0.5  # [l0]: a 2 l0 climb in about 6 jumps
    q_state: float = 1.0  # per (sqrt(g l0))², against l0² of height
    zeta0_range: tuple[float, float] = (HeightController.zeta0_min, HeightController.zeta0_max)
    psi0_range_deg: tuple[float, float] = PSI0_RANGE_DEG
    guard: tuple[float, ...] = ()  # the viability kernel it never leaves (sim_core.viability.guard); () for none

    name = "deadbeat"

    def __post_init__(self) -> None:
        check_range("target", self.target, 0.0, 1e4)
        check_range("climb_per_jump", self.climb_per_jump, 0.0, 10.0)
        check_range("q_state", self.q_state, 0.0, 1e6, low_open=False)
        _check_interval("zeta0_range", self.zeta0_range, 1.0)
        _check_interval("psi0_range_deg", self.psi0_range_deg, 90.0)
        check_range("psi0_deg", self.psi0_deg, *self.psi0_range_deg, low_open=False, high_open=False)
        check_range("zeta0", self.zeta0, *self.zeta0_range, low_open=False, high_open=False)
        for field, values, size in (("state", self.state, 2), ("model", self.model, 5)):
            if len(values) != size or not all(math.isfinite(value) for value in values):
                raise ParameterError(field, f"must be {size} finite numbers, got {values!r}")
        if self.guard and len(self.guard) != 2 + int(self.guard[0]) + int(self.guard[1]) * (1 + int(self.guard[0])):
            raise ParameterError("guard", "must be a viability guard's layout (sim_core.viability.guard.design_guard)")

    def kernel_args(self) -> tuple[int, np.ndarray]:
        """``(kind, parameters)`` for :func:`sim_core.control.controllers.control_step`, in
        :mod:`sim_core.control.deadbeat`'s layout."""
        psi0_low, psi0_high = (math.radians(value) for value in self.psi0_range_deg)
        parameters = [self.target, math.radians(self.psi0_deg), self.zeta0, *self.zeta0_range, psi0_low, psi0_high,
                      self.climb_per_jump, 1.0, *self.model, *self.state, self.q_state, *self.guard]  # fmt: skip
        return DEADBEAT, np.array(parameters)


Controller = Pid | Lqr | Deadbeat  # what every front end hands the compiled loop


def _check_interval(field: str, interval: tuple[float, float], bound: float) -> None:
    low, high = interval
    check_range(field, low, 0.0, bound)
    check_range(field, high, 0.0, bound)
    if not low < high:
        raise ParameterError(field, f"must be an interval (low < high), got [{low:g}, {high:g}]")
