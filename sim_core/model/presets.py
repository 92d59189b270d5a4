"""Named parameter sets, the paper's gaits and the usual first guess of a section state.
Presets are data: add one here and every command, the API and the GUI can use it by name.

``paper`` is Table I of the ICRA 2011 paper. The extracted text lost ``l0``; it keeps
``d_hat = 2.42``, so ``l0 = d / 2.42`` (docs/model.md §1).

:data:`PAPER_GAITS` are the stable gaits of period 1, 2 and 4 of the paper's Fig. 7 (docs/model.md
§5), each as the ``(psi0_deg, zeta0)`` pairs of its control schedule (one pair: both legs; two:
L, R), the form :meth:`ControlSchedule.from_degrees` takes and JSON keeps. The paper does not
give period 4's right-leg zeta0: 0.9505 is the middle of the band where ``experiments/fig7.py``'s
scan finds a period-4 attractor (docs/analyses.md).
"""

from __future__ import annotations

from dataclasses import replace
from types import MappingProxyType

from sim_core.model.params import ModelParams, PhysicalParams
from sim_core.model.validation import ParameterError

PRESETS = MappingProxyType(
    {
        "paper": PhysicalParams(
            mass=1.54,
            leg_length=0.54 / 2.42,
            stiffness=525.0,
            wall_distance=0.54,
            gravity=0.98,
            c_zeta=1.0,
            c_psi=1.0,
            mu=2.0,
        ),
    }
)

DEFAULT_PRESET = "paper"

PAPER_GAITS = MappingProxyType(
    {
        "period 1": ((30.0, 0.90),),
        "period 2": ((30.0, 0.87), (30.0, 0.90)),
        "period 4": ((30.0, 0.90), (35.0, 0.9505)),
    }
)

# A section state (xdot, ydot) [sqrt(g l0)] near the paper's period-1 gait (30°, 0.9): the guess
# Levenberg–Marquardt starts from, and where a climb starts when there is no gait to start on.
START_GUESS = (-0.93, -0.2)


def get_preset(name: str) -> PhysicalParams:
    """The physical parameters of preset ``name``; a clear error names the known presets."""
    try:
        return PRESETS[name]
    except KeyError:
        known = ", ".join(sorted(PRESETS))
        raise ParameterError("preset", f"unknown preset {name!r}; known presets: {known}") from None


def preset_model(name: str, *, field: str = "preset", **overrides: float | None) -> ModelParams:
    """Built-in preset ``name``'s nondimensional model with every non-None override applied (a
    ParameterError on each out-of-range one); an unknown name is a ParameterError on ``field``
    naming the known presets."""
    if name not in PRESETS:
        raise ParameterError(field, f"unknown preset {name!r}; known presets: {', '.join(sorted(PRESETS))}")
    return replace(PRESETS[name].to_model(), **{key: value for key, value in overrides.items() if value is not None})
