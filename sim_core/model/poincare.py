"""The Poincaré map, validated and typed (docs/model.md §4).

The section is touchdown on the left wall after the coordinate flip; its state is
``q = (xdot, ydot)`` in units of ``sqrt(g l0)``, with ``xdot < 0`` (flying toward the wall).
:func:`iterate_map` applies the map ``jumps`` times from one state; :func:`iterate_map_batch`
does the same for many states on all cores.

>>> import math
>>> from sim_core import ControlSchedule, get_preset, iterate_map
>>> orbit = iterate_map(get_preset("paper").to_model(),
...                     ControlSchedule.from_degrees([(30, 0.9)]), (-1.0, 0.5), jumps=3)
>>> orbit.failure is None, orbit.states.shape
(True, (4, 2))
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from sim_core.model import stride
from sim_core.model.controls import ControlSchedule
from sim_core.model.failures import OK, Failure
from sim_core.model.params import ModelParams
from sim_core.model.validation import ParameterError, check_range

MAX_JUMPS = 1_000_000


def check_section_state(state) -> np.ndarray:
    """``(xdot, ydot)`` as a float array, or a :class:`ParameterError` naming the bad part."""
    values = np.asarray(state, dtype=np.float64)
    if values.shape != (2,):
        raise ParameterError("state", f"must be two numbers (xdot, ydot), got shape {values.shape}")
    check_range("state.xdot", values[0], high=0.0)
    check_range("state.ydot", values[1])
    return values


def check_jumps(jumps: int, field: str = "jumps") -> int:
    if isinstance(jumps, bool) or int(jumps) != jumps or not 0 <= jumps <= MAX_JUMPS:
        raise ParameterError(field, f"must be an integer in [0, {MAX_JUMPS}], got {jumps!r}")
    return int(jumps)


@dataclass(frozen=True)
class Orbit:
    """The section states of one run of the map.

    Attributes:
        states: shape (k + 1, 2), the starting state then one state per completed jump.
        rises: shape (k,), height gain of each completed jump [l0].
        failure: why the run stopped early, or None if all jumps completed.
        failed_jump: 1-based number of the jump that failed (``k + 1``), or None.
    """

    states: np.ndarray
    rises: np.ndarray
    failure: Failure | None
    failed_jump: int | None

    @property
    def jumps_completed(self) -> int:
        return self.rises.shape[0]

    def to_dict(self) -> dict:
        """The ``parkour map --json`` contract."""
        failure = None
        if self.failure is not None:
            failure = {"code": self.failure.code, "jump": self.failed_jump}
        return {
            "states": self.states.tolist(),
            "rises": self.rises.tolist(),
            "failure": failure,
        }


@dataclass(frozen=True)
class OrbitBatch:
    """Many orbits of equal length. Rows after a failure are NaN.

    Attributes:
        states: shape (N, jumps + 1, 2). rises: shape (N, jumps).
        status: shape (N,) int, 0 for success else a :class:`Failure` value.
        completed: shape (N,) int, jumps completed before the failure (or ``jumps``).
    """

    states: np.ndarray
    rises: np.ndarray
    status: np.ndarray
    completed: np.ndarray

    def failure(self, index: int) -> Failure | None:
        code = int(self.status[index])
        return None if code == OK else Failure(code)


def iterate_map(model: ModelParams, schedule: ControlSchedule, state, jumps: int, *, first_jump: int = 0) -> Orbit:
    """Apply the Poincaré map ``jumps`` times from section state ``state = (xdot, ydot)``.

    Jump ``k`` uses ``schedule[first_jump + k]``. A failing jump ends the run; the result
    says which jump failed and why.
    """
    initial = check_section_state(state)
    jumps = check_jumps(jumps)
    states = np.empty((jumps + 1, 2))
    rises = np.empty(jumps)
    status, completed = stride.orbit(
        initial[0], initial[1], schedule.as_array(), first_jump, model.record(), states, rises
    )
    if status == OK:
        return Orbit(states=states, rises=rises, failure=None, failed_jump=None)
    return Orbit(
        states=states[: completed + 1].copy(),
        rises=rises[:completed].copy(),
        failure=Failure(status),
        failed_jump=completed + 1,
    )


def iterate_map_batch(
    model: ModelParams,
    schedules: ControlSchedule | np.ndarray,
    states,
    jumps: int,
    *,
    first_jump: int = 0,
) -> OrbitBatch:
    """Iterate many section states at once on all cores.

    Args:
        schedules: one schedule shared by all, or an array (N, m, 2) of per-start schedules
            (psi0 [rad], zeta0) — e.g. noisy controls for Monte-Carlo.
        states: shape (N, 2) section states. Non-finite or ``xdot >= 0`` rows fail with
            ``invalid_state`` instead of raising, so grids may include them.
    """
    initial = np.ascontiguousarray(np.asarray(states, dtype=np.float64))
    if initial.ndim != 2 or initial.shape[1] != 2:
        raise ParameterError("states", f"must have shape (N, 2), got {initial.shape}")
    jumps = check_jumps(jumps)
    if isinstance(schedules, ControlSchedule):
        schedule_array = schedules.as_array()[np.newaxis]
    else:
        schedule_array = np.ascontiguousarray(np.asarray(schedules, dtype=np.float64))
        if (
            schedule_array.ndim != 3
            or schedule_array.shape[2] != 2
            or schedule_array.shape[0]
            not in (
                1,
                initial.shape[0],
            )
        ):
            raise ParameterError("schedules", f"must have shape (1 or N, m, 2), got {schedule_array.shape}")
    count = initial.shape[0]
    out_states = np.empty((count, jumps + 1, 2))
    out_rises = np.empty((count, jumps))
    status = np.empty(count, dtype=np.int64)
    completed = np.empty(count, dtype=np.int64)
    stride.orbit_batch(initial, schedule_array, first_jump, model.record(), out_states, out_rises, status, completed)
    return OrbitBatch(states=out_states, rises=out_rises, status=status, completed=completed)


__all__ = [
    "Orbit",
    "OrbitBatch",
    "check_jumps",
    "check_section_state",
    "iterate_map",
    "iterate_map_batch",
]
