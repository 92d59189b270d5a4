"""The stance equations of motion (paper eq. 3, docs/model.md §2) on the integrator's state.

The state is a tuple ``(zeta, psi, zeta_dot, psi_dot, cos psi, sin psi, t)`` indexed by the
names below. Carrying ``cos psi`` and ``sin psi`` (with ``d cos psi/dt = -sin psi psi_dot``)
takes the trigonometry out of the thirteen right-hand-side evaluations per step, which made
the kernel 1.6x faster; ``t`` is there so Hénon's trick (:mod:`sim_core.model.integrate`) can
integrate it as a dependent variable.
"""

from __future__ import annotations

from sim_core._jit import kernel

ZETA = 0
PSI = 1
ZETA_DOT = 2
PSI_DOT = 3
COS_PSI = 4
SIN_PSI = 5
TIME = 6
STATE_SIZE = 7


@kernel
def rates(state, alpha, c_zeta, c_psi, independent):
    """Derivative of ``state`` with respect to ``state[independent]`` (``TIME``: the usual d/dt).

    Units are nondimensional: lengths in l0, time in sqrt(l0/g); ``alpha``, ``c_zeta`` and
    ``c_psi`` as in docs/model.md §1. Another independent variable ``s`` is Hénon's trick,
    ``d/ds = (d/dt) / (ds/dt)``; it is infinite or NaN where ``ds/dt = 0``, which the callers
    treat as a failed step.
    """
    zeta, _psi, zeta_dot, psi_dot, cos_psi, sin_psi, _time = state
    zeta_rate = zeta_dot
    psi_rate = psi_dot
    zeta_dot_rate = alpha * (1.0 - zeta) + zeta * psi_dot * psi_dot - sin_psi - c_zeta * zeta_dot
    psi_dot_rate = -(cos_psi + 2.0 * zeta_dot * psi_dot) / zeta - c_psi * psi_dot
    cos_rate = -sin_psi * psi_dot
    sin_rate = cos_psi * psi_dot
    if independent == TIME:
        return (zeta_rate, psi_rate, zeta_dot_rate, psi_dot_rate, cos_rate, sin_rate, 1.0)
    rate = (zeta_rate, psi_rate, zeta_dot_rate, psi_dot_rate, cos_rate, sin_rate, 1.0)
    scale = 1.0 / rate[independent]
    scaled = (
        zeta_rate * scale,
        psi_rate * scale,
        zeta_dot_rate * scale,
        psi_dot_rate * scale,
        cos_rate * scale,
        sin_rate * scale,
        scale,
    )
    # Exactly 1 in the independent coordinate, as the trick requires.
    return replace_item(scaled, independent, 1.0)


@kernel
def replace_item(values, index, value):
    """``values`` (a 7-tuple) with item ``index`` replaced by ``value``."""
    return (
        value if index == 0 else values[0],
        value if index == 1 else values[1],
        value if index == 2 else values[2],
        value if index == 3 else values[3],
        value if index == 4 else values[4],
        value if index == 5 else values[5],
        value if index == 6 else values[6],
    )
