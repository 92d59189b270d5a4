"""Periodic gaits: fixed points of the Poincaré map and their stability (docs/model.md §4).

Which gait a caller means — from a guess, or the most stable of a grid search — is decided in
:mod:`sim_core.section.gait_search` (:func:`~sim_core.section.gait_search.gait_of`); this module finds and
describes one fixed point.

A period-n fixed point satisfies ``P^n(q) = q``; n must be a multiple of the schedule's
length. It is found by Levenberg–Marquardt (MINPACK, as the paper) on ``P^n(q) - q``. Its
Jacobian ``DP^n`` comes from 4th-order central differences (a 5-point stencil) instead of the
paper's forward differences: truncation error O(h^4) with h = 1e-3 sits below the
integrator's 1e-12 noise amplified by 1/h, so the eigenvalues are good to about 1e-8.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from sim_core.model import stride
from sim_core.model.controls import ControlSchedule
from sim_core.model.errors import FixedPointNotFound
from sim_core.model.failures import OK, Failure
from sim_core.model.params import ModelParams
from sim_core.model.poincare import check_section_state, iterate_map
from sim_core.model.validation import ParameterError

RESIDUAL_TOL = 1e-9  # |P^n(q) - q| accepted as a fixed point [sqrt(g l0)]
PERIOD_TOL = 1e-7  # |P^p(q) - q| below which p is a period of a found fixed point
JACOBIAN_STEP = 1e-3  # central-difference step, relative to max(1, |q_i|)
IN_PLACE_TOL = 1e-6  # |climb per jump| [l0] below which a gait jumps in place
_FAILED_RESIDUAL = 1e3  # residual of a trial point whose orbit fails: LM rejects the step


@dataclass(frozen=True)
class FixedPoint:
    """A periodic gait.

    Attributes:
        state: section state ``(xdot, ydot)`` on the orbit, at the schedule's first jump.
        period: minimal period p in jumps (a multiple of the schedule length).
        orbit: shape (p, 2), the section states along one period, starting at ``state``.
        rises: shape (p,), height gain of each jump of the period [l0].
        jacobian: ``DP^p(state)``, shape (2, 2).
        eigenvalues: shape (2,) complex, eigenvalues of ``jacobian`` (Floquet multipliers).
        residual: ``|P^n(state) - state|`` for the requested n, 2-norm.
    """

    state: np.ndarray
    period: int
    orbit: np.ndarray
    rises: np.ndarray
    jacobian: np.ndarray
    eigenvalues: np.ndarray
    residual: float

    @property
    def max_abs_eigenvalue(self) -> float:
        return float(np.max(np.abs(self.eigenvalues)))

    @property
    def stable(self) -> bool:
        """Locally asymptotically stable: both eigenvalues strictly inside the unit circle."""
        return self.max_abs_eigenvalue < 1.0

    @property
    def climb_per_period(self) -> float:
        """Height gained over one period [l0]."""
        return float(np.sum(self.rises))

    @property
    def motion(self) -> str:
        """``"climbing"``, ``"in place"`` or ``"descending"``."""
        per_jump = self.climb_per_period / self.period
        if abs(per_jump) <= IN_PLACE_TOL:
            return "in place"
        return "climbing" if per_jump > 0 else "descending"

    def to_dict(self) -> dict:
        """The gait as JSON types: the ``parkour fixed-point --json`` contract, one gait of
        ``parkour gaits --json`` and of the API's answers. ``orbit`` is a list of p pairs."""
        return {
            "state": self.state.tolist(),
            "period": self.period,
            "eigenvalues": [[float(z.real), float(z.imag)] for z in self.eigenvalues],
            "max_abs_eigenvalue": self.max_abs_eigenvalue,
            "stable": self.stable,
            "climb_per_period": self.climb_per_period,
            "residual": self.residual,
            "motion": self.motion,
            "orbit": self.orbit.tolist(),
        }


def check_period(schedule: ControlSchedule, period: int) -> int:
    if isinstance(period, bool) or int(period) != period or not 1 <= period <= 64:
        raise ParameterError("period", f"must be an integer in [1, 64], got {period!r}")
    if period % len(schedule) != 0:
        raise ParameterError(
            "period",
            f"must be a multiple of the control schedule's length {len(schedule)}, got {period}",
        )
    return int(period)


class _MapPower:
    """``q -> P^n(q)`` through the compiled orbit kernel, reusing its buffers."""

    def __init__(self, model: ModelParams, schedule: ControlSchedule, jumps: int):
        self.model = model.record()
        self.schedule = schedule.as_array()
        self.states = np.empty((jumps + 1, 2))
        self.rises = np.empty(jumps)

    def __call__(self, state: np.ndarray) -> np.ndarray | None:
        """The state after n jumps, or None if a jump fails."""
        status, _ = stride.orbit(state[0], state[1], self.schedule, 0, self.model, self.states, self.rises)
        return self.states[-1].copy() if status == OK else None


def map_jacobian(
    model: ModelParams, schedule: ControlSchedule, state, jumps: int, *, step: float = JACOBIAN_STEP
) -> np.ndarray:
    """``D P^jumps`` at ``state`` by 4th-order central differences, shape (2, 2).

    Raises :class:`FixedPointNotFound` if the map fails anywhere on the stencil.
    """
    return _jacobian(_MapPower(model, schedule, jumps), check_section_state(state), step)


def _jacobian(power: _MapPower, state: np.ndarray, step: float) -> np.ndarray:
    jacobian = np.empty((2, 2))
    for column in range(2):
        h = step * max(1.0, abs(state[column]))
        images = []
        for offset in (2.0, 1.0, -1.0, -2.0):
            shifted = state.copy()
            shifted[column] += offset * h
            image = power(shifted)
            if image is None:
                raise FixedPointNotFound(
                    f"the map fails within {2 * h:.1e} of the state {state.tolist()}; "
                    "the orbit lies on the edge of failure"
                )
            images.append(image)
        plus2, plus1, minus1, minus2 = images
        jacobian[:, column] = (-plus2 + 8.0 * plus1 - 8.0 * minus1 + minus2) / (12.0 * h)
    return jacobian


def find_fixed_point(
    model: ModelParams,
    schedule: ControlSchedule,
    period: int,
    guess,
    *,
    max_evaluations: int = 400,
) -> FixedPoint:
    """A period-``period`` fixed point near ``guess = (xdot, ydot)`` by Levenberg–Marquardt.

    The returned gait reports its minimal period, which may divide ``period``.
    Raises :class:`FixedPointNotFound` with the reason when it does not converge.
    """
    from scipy.optimize import least_squares  # a quarter second to import: loaded when first solved

    period = check_period(schedule, period)
    start = check_section_state(guess)
    power = _MapPower(model, schedule, period)
    if power(start) is None:
        orbit_failure = _first_failure(model, schedule, start, period)
        raise FixedPointNotFound(f"the map fails from the guess {start.tolist()}: {orbit_failure}")

    def residual(q: np.ndarray) -> np.ndarray:
        image = power(q) if q[0] < 0.0 else None
        return np.full(2, _FAILED_RESIDUAL) if image is None else image - q

    def residual_jacobian(q: np.ndarray) -> np.ndarray:
        try:
            return _jacobian(power, q, JACOBIAN_STEP) - np.eye(2)
        except FixedPointNotFound:
            return np.eye(2)  # a failing stencil: any full-rank matrix lets LM shrink its step

    solution = least_squares(
        residual,
        start,
        jac=residual_jacobian,
        method="lm",
        xtol=1e-15,
        ftol=1e-15,
        gtol=1e-15,
        max_nfev=max_evaluations,
    )
    state = solution.x
    image = power(state) if state[0] < 0.0 else None
    error = np.inf if image is None else float(np.linalg.norm(image - state))
    if not error <= RESIDUAL_TOL:
        raise FixedPointNotFound(
            f"no period-{period} fixed point found from {start.tolist()}: "
            f"residual {error:.2e} after {solution.nfev} map evaluations"
        )
    return characterize(model, schedule, state, period, residual=error)


def characterize(
    model: ModelParams, schedule: ControlSchedule, state, period: int, *, residual: float | None = None
) -> FixedPoint:
    """Minimal period, orbit, climb and eigenvalues of a fixed point of ``P^period``."""
    state = check_section_state(state)
    minimal = minimal_period(model, schedule, state, period)
    power = _MapPower(model, schedule, minimal)
    if power(state) is None:
        raise FixedPointNotFound(f"the map fails from {state.tolist()}")
    orbit_states, rises = power.states[:-1].copy(), power.rises.copy()
    jacobian = _jacobian(power, state, JACOBIAN_STEP)
    if residual is None:
        image = _MapPower(model, schedule, period)(state)
        residual = float(np.linalg.norm(image - state))
    return FixedPoint(
        state=state.copy(),
        period=minimal,
        orbit=orbit_states,
        rises=rises,
        jacobian=jacobian,
        eigenvalues=np.linalg.eigvals(jacobian),
        residual=residual,
    )


def minimal_period(model: ModelParams, schedule: ControlSchedule, state, period: int) -> int:
    """Smallest p dividing ``period`` (and a multiple of the schedule length) with P^p(q) = q."""
    state = check_section_state(state)
    period = check_period(schedule, period)
    for candidate in range(len(schedule), period, len(schedule)):
        if period % candidate:
            continue
        image = _MapPower(model, schedule, candidate)(state)
        if image is not None and np.linalg.norm(image - state) <= PERIOD_TOL * (1.0 + np.linalg.norm(state)):
            return candidate
    return period


def _first_failure(model: ModelParams, schedule: ControlSchedule, state: np.ndarray, jumps: int) -> str:
    orbit = iterate_map(model, schedule, state, jumps)
    failure: Failure | None = orbit.failure
    if failure is None:
        return "no failure"
    return f"{failure.code} at jump {orbit.failed_jump} ({failure.message})"
