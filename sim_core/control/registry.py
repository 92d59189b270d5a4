"""The controllers' registry: every law closed once per jump by name — its branch in the compiled
dispatch, a one-line summary and its design — the one list the CLI's choices, the API's enum,
the panel (through the API's catalog), the live run and the 3D view read. Light: a design loads
its kernels (the LQR's Riccati solver, the deadbeat's predictions) only when it is called.

Adding a controller: its law as data (a module of :mod:`sim_core.control.laws`: a frozen
dataclass with ``name`` and ``kernel_args()``, and its ``NUMBER``), its step and branch in
:func:`sim_core.control.controllers.control_step` (numba caches a static dispatch only: a law
handed to the compiled loop as a function compiles again in every process), its line in
:data:`LAWS` here, and its test. Nothing else names it.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import dataclass, replace

from sim_core.control.laws import Controller, Deadbeat, DesignRequest, Placement, deadbeat, lqr, pid
from sim_core.control.laws.pid import Pid
from sim_core.model.validation import ParameterError


@dataclass(frozen=True)
class LawKind:
    """A registered law: its ``name`` (what the CLI, the API, the panel and the 3D view show and
    accept), ``number`` (its branch in the compiled dispatch), a one-line ``summary`` for choosers,
    and ``design``, which builds the law's parameters for a :class:`DesignRequest`.
    ``sets_leg_angle``: False for a law that leaves the leg angle where the leg holds it (the plain
    PID: on the robot, the angle is not commanded at all)."""

    name: str
    number: int
    summary: str
    design: Callable[[DesignRequest], Controller]
    sets_leg_angle: bool = True


def _pid(pitch_feedback: bool) -> Callable[[DesignRequest], Controller]:
    def design(request: DesignRequest) -> Controller:
        return Pid(request.height, request.psi0_deg, pitch_feedback=pitch_feedback,
                   psi0_range_deg=request.psi0_range_deg)  # fmt: skip

    return design


def _lqr(request: DesignRequest) -> Controller:
    from sim_core.control.return_map_lqr import design_lqr  # scipy's Riccati solver, only when asked

    height = request.height
    law = design_lqr(request.model, height.target, request.psi0_deg, height.zeta0_hover,
                     zeta0_range=request.zeta0_range)  # fmt: skip
    return replace(law, psi0_range_deg=request.psi0_range_deg)


def _horizon(law: type[Deadbeat]) -> Callable[[DesignRequest], Controller]:
    def design(request: DesignRequest) -> Controller:
        from sim_core.control.deadbeat import design_deadbeat  # the compiled predictions, only when asked

        height = request.height
        return design_deadbeat(request.model, height.target, request.psi0_deg, height.zeta0_hover,
                               zeta0_range=request.zeta0_range, climb_per_jump=request.climb_per_jump,
                               psi0_range_deg=request.psi0_range_deg, law=law)  # fmt: skip

    return design


LAWS: dict[str, LawKind] = {
    law.name: law
    for law in (
        LawKind("pid", pid.NUMBER, "PID on the touchdown height", _pid(False), sets_leg_angle=False),
        LawKind("pid-pitch", pid.PITCH_NUMBER, "PID, the tracked pitch fed to the leg angle", _pid(True)),
        LawKind("lqr", lqr.NUMBER, "LQR on the model's return map", _lqr),
        LawKind("deadbeat", deadbeat.NUMBER, "two jumps ahead on the model, guarded", _horizon(Deadbeat)),
        LawKind(
            "placement",
            deadbeat.PLACEMENT_NUMBER,
            "each foot placed two jumps ahead, angle and length",
            _horizon(Placement),
        ),
    )
}
NAMES: tuple[str, ...] = tuple(LAWS)
KINDS: dict[str, int] = {law.name: law.number for law in LAWS.values()}  # name -> its compiled branch


def law_kind(name: str, field: str = "controller") -> LawKind:
    """The registered law ``name``; a ParameterError naming ``field`` and the choices otherwise."""
    if name not in LAWS:
        raise ParameterError(field, f"must be among {', '.join(NAMES)}, got {name!r}")
    return LAWS[name]


def check_names(names: Iterable[str], field: str = "controllers") -> tuple[str, ...]:
    """``names`` if at least one, each registered and named once; a ParameterError naming ``field``."""
    names = tuple(names)
    if not names:
        raise ParameterError(field, f"must name at least one of {', '.join(NAMES)}")
    for name in names:
        law_kind(name, field)
    if len(set(names)) != len(names):
        raise ParameterError(field, f"names a controller twice: {', '.join(names)}")
    return names


def design(name: str, request: DesignRequest) -> Controller:
    """The law ``name`` designed for ``request`` (a ParameterError naming ``controller`` if unknown)."""
    return law_kind(name).design(request)
