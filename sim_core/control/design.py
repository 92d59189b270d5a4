"""A named controller built for one model — a registered law's name (:data:`sim_core.control.registry.LAWS`)
and the height loop's settings turned into the law the compiled loop runs — and
:class:`SteppedLaw`, a law stepped one touchdown at a time by one owner (a live run's loop, the
3D view's climb).

The benchmark (:mod:`experiments.control_study`) and the robot's live run both build their laws
here, so a calibrated preset gives the same controller on the robot as in the study: the LQR's
gains from that model's return map (:func:`sim_core.control.return_map_lqr.design_lqr`), the deadbeat's
predictions from that model (:func:`sim_core.control.deadbeat.design_deadbeat`), the PIDs about its
in-place zeta0.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from sim_core.control.height_controller import HeightController
from sim_core.control.laws import DEADBEAT_CLIMB_PER_JUMP, PSI0_RANGE_DEG, Controller, DesignRequest
from sim_core.control.registry import design
from sim_core.model.controls import LegControl
from sim_core.model.params import ModelParams

Command = tuple[float, float, bool]  # the next touchdown's psi0 [rad] and zeta0, and whether it was clipped


def design_law(
    name: str,
    model: ModelParams,
    height: HeightController,
    psi0_deg: float,
    *,
    psi0_range_deg: tuple[float, float] = PSI0_RANGE_DEG,
    climb_per_jump: float = DEADBEAT_CLIMB_PER_JUMP,
) -> Controller:
    """The law ``name`` (one of :data:`sim_core.control.registry.LAWS`) holding ``height.target`` [l0]
    about the gait of jumping in place at ``psi0_deg`` with ``height.zeta0_hover``, its leg length
    within the height loop's range and its leg angle within ``psi0_range_deg`` (the servos'); the
    PIDs take ``height``'s gains. A ParameterError naming ``controller`` for an unknown name, or
    the field a law refuses."""
    return design(name, DesignRequest(model, height, psi0_deg, psi0_range_deg, climb_per_jump))


def law_holding(
    name: str,
    model: ModelParams,
    target: float,
    psi0_deg: float,
    *,
    gains: tuple[float, float, float] = (HeightController.kp, HeightController.ki, HeightController.kd),
    zeta0_range: tuple[float, float] = (HeightController.zeta0_min, HeightController.zeta0_max),
    psi0_range_deg: tuple[float, float] = PSI0_RANGE_DEG,
    climb_per_jump: float = DEADBEAT_CLIMB_PER_JUMP,
) -> Controller:
    """:func:`design_law` about the zeta0 of jumping in place at ``psi0_deg`` on ``model`` (found
    within ``zeta0_range``), holding ``target`` [l0]; ``gains`` ``(kp, ki, kd)`` for the PIDs."""
    from sim_core.basins.sweep import find_in_place_zeta0  # the gait search's kernels, only when asked

    hover = find_in_place_zeta0(model, math.radians(psi0_deg), zeta0_range=zeta0_range)
    height = HeightController(target, hover, *gains, *zeta0_range)
    return design_law(name, model, height, psi0_deg, psi0_range_deg=psi0_range_deg, climb_per_jump=climb_per_jump)


@dataclass
class SteppedLaw:
    """``law`` stepped at each touchdown, its memory kept between steps: the compiled
    :func:`sim_core.control.controllers.control_step`, compiled (or loaded from numba's cache) when this is
    made, so a first touchdown never waits for it. ``first``: the controls of the touchdown before
    the first step (the LQR's and deadbeat's "last command"). One owner: not for two threads."""

    law: Controller
    first: LegControl
    memory: np.ndarray = field(init=False)

    def __post_init__(self) -> None:
        from sim_core.control.controllers import control_step, new_memory

        self._control_step = control_step
        self.kind, self.parameters = self.law.kernel_args()
        self.memory = new_memory(self.kind, self.first.psi0, self.first.zeta0)
        control_step(self.kind, self.parameters, self.memory.copy(), 1.0, 0.0, -0.9, -0.2, True)  # compiled now

    @property
    def name(self) -> str:
        return self.law.name

    def step(
        self, height: float, pitch: float, xdot: float, ydot: float, next_on_left: bool
    ) -> tuple[float, float, bool]:
        """The next touchdown's ``(psi0 [rad], zeta0, clipped)`` from this one's body ``height``
        [l0], tracked ``pitch`` [rad] (NaN: none) and section state; ``next_on_left``: the next
        touchdown is on the left wall."""
        psi0, zeta0, clipped = self._control_step(self.kind, self.parameters, self.memory, height, pitch, xdot, ydot,
                                                  next_on_left)  # fmt: skip
        return float(psi0), float(zeta0), bool(clipped)

    @property
    def state(self) -> list[float | None]:
        """The law's memory after the last step, as JSON keeps it (NaN as None)."""
        return [None if math.isnan(value) else float(value) for value in self.memory]
