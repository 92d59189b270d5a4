"""Request bodies as the API takes them, from what a script finds natural to write: a leg's
controls as ``(psi0 [deg], zeta0 [l0])``, a section state as ``(xdot, ydot)`` [sqrt(g l0)]."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

Leg = tuple[float, float] | Mapping[str, float]  # (psi0 [deg], zeta0 [l0]) or {"psi0_deg": …, "zeta0": …}
State = tuple[float, float] | Mapping[str, float]  # (xdot, ydot) [sqrt(g l0)] or {"xdot": …, "ydot": …}


def legs(controls: Sequence[Leg]) -> list[dict[str, float]]:
    """A control schedule as the API takes it: ``[{"psi0_deg", "zeta0"}, …]``.

    >>> legs([(30, 0.87), {"psi0_deg": 30, "zeta0": 0.9}])
    [{'psi0_deg': 30, 'zeta0': 0.87}, {'psi0_deg': 30, 'zeta0': 0.9}]
    """
    return [dict(leg) if isinstance(leg, Mapping) else {"psi0_deg": leg[0], "zeta0": leg[1]} for leg in controls]


def state(start: State | None) -> dict[str, float] | None:
    """A section state as the API takes it: ``{"xdot", "ydot"}`` (None stays None)."""
    if start is None:
        return None
    return dict(start) if isinstance(start, Mapping) else {"xdot": start[0], "ydot": start[1]}


def mapping(value: Mapping[str, Any] | None) -> dict[str, Any] | None:
    """A mapping as a plain dict (None stays None)."""
    return None if value is None else dict(value)


def present(body: Mapping[str, Any]) -> dict[str, Any]:
    """``body`` without its None values: the service's defaults apply to what is left out."""
    return {name: value for name, value in body.items() if value is not None}
