"""The deadbeat law (``deadbeat``): zeta0 chosen two jumps ahead on the design model's own map,
behind a guard that never sends a command the model predicts fails
(:mod:`sim_core.control.deadbeat` computes and steps it)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from sim_core.control.height_controller import HeightController
from sim_core.control.laws.common import DEADBEAT_CLIMB_PER_JUMP, PSI0_RANGE_DEG, check_interval
from sim_core.model.validation import ParameterError, check_range

NUMBER = 3  # its branch in the compiled dispatch


@dataclass(frozen=True)
class Deadbeat:
    """The deadbeat law on a short horizon with a safety guard (:mod:`sim_core.control.deadbeat`; built by
    :func:`sim_core.control.deadbeat.design_deadbeat`): zeta0 chosen each jump by the design model
    (``model``: ``(alpha, d_hat, c_zeta, c_psi, mu)``, :meth:`sim_core.model.params.ModelParams.record`'s order)
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
    climb_per_jump: float = DEADBEAT_CLIMB_PER_JUMP  # [l0]
    q_state: float = 1.0  # per (sqrt(g l0))², against l0² of height
    zeta0_range: tuple[float, float] = (HeightController.zeta0_min, HeightController.zeta0_max)
    psi0_range_deg: tuple[float, float] = PSI0_RANGE_DEG
    guard: tuple[float, ...] = ()  # the viability kernel it never leaves (sim_core.viability.guard); () for none

    name = "deadbeat"
    number = NUMBER
    angle_step_deg = 0.0  # [deg] the angle is held (the placement law steps it: :class:`Placement`)

    def __post_init__(self) -> None:
        check_range("target", self.target, 0.0, 1e4)
        check_range("climb_per_jump", self.climb_per_jump, 0.0, 10.0)
        check_range("q_state", self.q_state, 0.0, 1e6, low_open=False)
        check_interval("zeta0_range", self.zeta0_range, 1.0)
        check_interval("psi0_range_deg", self.psi0_range_deg, 90.0)
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
                      self.climb_per_jump, 1.0, *self.model, *self.state, self.q_state,
                      math.radians(self.angle_step_deg), *self.guard]  # fmt: skip
        return self.number, np.array(parameters)


PLACEMENT_NUMBER = 4  # the placement law's branch in the compiled dispatch


@dataclass(frozen=True)
class Placement(Deadbeat):
    """The foot-placement law between parallel walls (``placement``): as :class:`Deadbeat`, the
    next foot placed two jumps ahead on the design model, but over both legs — the leg angle at the
    gait's and ``angle_step_deg`` either side of it, each with zeta0 over its range — and a lighter
    weight on the state (``q_state``) so that the feet's heights lead. Between parallel walls every
    foothold is the other wall, so placing the next foot is placing it at a height; on footholds
    the same law's world form follows a plan (:mod:`sim_core.control.placement`)."""

    q_state: float = 0.3  # per (sqrt(g l0))², against l0² of height (docs/analyses.md: 0.1 falls, 1 holds looser)
    angle_step_deg: float = 3.0

    name = "placement"
    number = PLACEMENT_NUMBER

    def __post_init__(self) -> None:
        super().__post_init__()
        check_range("angle_step_deg", self.angle_step_deg, 0.0, 15.0, low_open=False)
