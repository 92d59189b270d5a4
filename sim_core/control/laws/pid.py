"""The PID on the touchdown height (``pid``), and the same with the tracked pitch fed to the leg
angle (``pid-pitch``): the paper's controller and its first repair (docs/analyses.md, "Controllers").
Compiled step: :func:`sim_core.control.controllers.control_step`'s PID branch."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from sim_core.control.height_controller import HeightController
from sim_core.control.laws.common import PSI0_RANGE_DEG, check_interval
from sim_core.model.validation import check_range

NUMBER, PITCH_NUMBER = 0, 1  # their branches in the compiled dispatch


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
        check_interval("psi0_range_deg", self.psi0_range_deg, 90.0)
        check_range("psi0_deg", self.psi0_deg, *self.psi0_range_deg, low_open=False, high_open=False)

    @property
    def name(self) -> str:
        return "pid-pitch" if self.pitch_feedback else "pid"

    @property
    def target(self) -> float:
        return self.height.target

    def kernel_args(self) -> tuple[int, np.ndarray]:
        """``(kind, parameters)`` for :func:`sim_core.control.controllers.control_step`."""
        height = self.height
        low, high = (math.radians(value) for value in self.psi0_range_deg)
        parameters = [height.target, height.zeta0_hover, height.kp, height.ki, height.kd, height.zeta0_min,
                      height.zeta0_max, math.radians(self.psi0_deg), low, high, float(self.pitch_feedback)]  # fmt: skip
        return PITCH_NUMBER if self.pitch_feedback else NUMBER, np.array(parameters)
