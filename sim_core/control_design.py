"""A named controller built for one model: the one place that turns a name (``pid``, ``pid-pitch``,
``lqr``, ``deadbeat``) and the height loop's settings into the law the compiled loop runs.

The benchmark (:mod:`experiments.control_study`) and the robot's live run both build their laws
here, so a calibrated preset gives the same controller on the robot as in the study: the LQR's
gains from that model's return map (:func:`sim_core.return_map_lqr.design_lqr`), the deadbeat's
predictions from that model (:func:`sim_core.deadbeat.design_deadbeat`), the PIDs about its
in-place zeta0.
"""

from __future__ import annotations

from dataclasses import replace

from sim_core.control_laws import KINDS, PSI0_RANGE_DEG, Controller, Pid
from sim_core.height_controller import HeightController
from sim_core.params import ModelParams
from sim_core.validation import ParameterError

DEADBEAT_CLIMB_PER_JUMP = 0.5  # [l0], sim_core.control_laws.Deadbeat's default


def design_law(
    name: str,
    model: ModelParams,
    height: HeightController,
    psi0_deg: float,
    *,
    psi0_range_deg: tuple[float, float] = PSI0_RANGE_DEG,
    climb_per_jump: float = DEADBEAT_CLIMB_PER_JUMP,
) -> Controller:
    """The law ``name`` holding ``height.target`` [l0] about the gait of jumping in place at
    ``psi0_deg`` with ``height.zeta0_hover``, its leg length within the height loop's range and
    its leg angle within ``psi0_range_deg`` (the servos'); the PIDs take ``height``'s gains. A
    ParameterError naming ``controller`` for an unknown name, or the field a law refuses."""
    if name not in KINDS:
        raise ParameterError("controller", f"must be among {', '.join(KINDS)}, got {name!r}")
    zeta0_range = (height.zeta0_min, height.zeta0_max)
    if name == "lqr":
        from sim_core.return_map_lqr import design_lqr  # scipy's Riccati solver, only when asked

        return replace(design_lqr(model, height.target, psi0_deg, height.zeta0_hover, zeta0_range=zeta0_range),
                       psi0_range_deg=psi0_range_deg)  # fmt: skip
    if name == "deadbeat":
        from sim_core.deadbeat import design_deadbeat

        return design_deadbeat(model, height.target, psi0_deg, height.zeta0_hover, zeta0_range=zeta0_range,
                               climb_per_jump=climb_per_jump, psi0_range_deg=psi0_range_deg)  # fmt: skip
    return Pid(height, psi0_deg, pitch_feedback=name == "pid-pitch", psi0_range_deg=psi0_range_deg)
