"""The controllers closed once per jump, as data: their names and kinds, the leg's range, and each
law's parameters (:class:`Pid`), checked. NumPy only, so the command line and the request schemas
read them without loading the kernels; the compiled law is :mod:`sim_core.controllers`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from sim_core.height_controller import HeightController
from sim_core.validation import ParameterError, check_range

PID, PID_PITCH = 0, 1
KINDS = {"pid": PID, "pid-pitch": PID_PITCH}
# The leg angle's range relative to the body [deg]: the robot's angle servos (backend/robot/limits.py).
PSI0_RANGE_DEG = (10.0, 60.0)
MEMORY_SIZE = 2  # a law's state between touchdowns: the PID's integral and its previous error


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
        low, high = self.psi0_range_deg
        check_range("psi0_range_deg", low, 0.0, 90.0)
        check_range("psi0_range_deg", high, 0.0, 90.0)
        if not low < high:
            raise ParameterError("psi0_range_deg", f"must be an interval (low < high), got [{low:g}, {high:g}]")
        check_range("psi0_deg", self.psi0_deg, low, high, low_open=False, high_open=False)

    @property
    def name(self) -> str:
        return "pid-pitch" if self.pitch_feedback else "pid"

    def kernel_args(self) -> tuple[int, np.ndarray]:
        """``(kind, parameters)`` for :func:`control_step`."""
        height = self.height
        low, high = (math.radians(value) for value in self.psi0_range_deg)
        parameters = [height.target, height.zeta0_hover, height.kp, height.ki, height.kd, height.zeta0_min,
                      height.zeta0_max, math.radians(self.psi0_deg), low, high, float(self.pitch_feedback)]  # fmt: skip
        return KINDS[self.name], np.array(parameters)
