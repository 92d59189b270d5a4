"""The LQR on the return map (``lqr``): both leg controls from the section state, the height error
and the last command, designed on the model's own map (:mod:`sim_core.control.return_map_lqr`).
Compiled step: :func:`sim_core.control.controllers.control_step`'s LQR branch."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from sim_core.control.height_controller import HeightController
from sim_core.control.laws.common import PSI0_RANGE_DEG, check_interval
from sim_core.model.validation import ParameterError, check_range

NUMBER = 2  # its branch in the compiled dispatch


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
        check_interval("zeta0_range", self.zeta0_range, 1.0)
        check_interval("psi0_range_deg", self.psi0_range_deg, 90.0)
        check_range("psi0_deg", self.psi0_deg, *self.psi0_range_deg, low_open=False, high_open=False)
        if len(self.gain) != 10 or not all(math.isfinite(value) for value in self.gain):
            raise ParameterError("gain", f"must be 10 finite numbers (2 x 5), got {len(self.gain)}")

    name = "lqr"

    def kernel_args(self) -> tuple[int, np.ndarray]:
        """``(kind, parameters)`` for :func:`sim_core.control.controllers.control_step`."""
        psi0_low, psi0_high = (math.radians(value) for value in self.psi0_range_deg)
        parameters = [self.target, math.radians(self.psi0_deg), self.zeta0, *self.state, *self.zeta0_range,
                      psi0_low, psi0_high, self.error_clip, 1.0, *self.gain, self.state_clip]  # fmt: skip
        return NUMBER, np.array(parameters)
