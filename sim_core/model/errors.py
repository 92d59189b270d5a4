"""The errors a user can fix, in one light module (no numba, no scipy).

Callers that only need to recognise these errors — the ``parkour`` command's error handler, the
API's error mapping — import them from here without loading the kernels.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from sim_core.model.controls import ControlSchedule


class ParameterError(ValueError):
    """A parameter, control or state is outside its allowed range.

    ``field`` is the name the user knows (``"zeta0"``, ``"alpha"``); the message says the
    allowed range and the value received.
    """

    def __init__(self, field: str, message: str):
        super().__init__(f"{field}: {message}")
        self.field = field
        self.message = message

    def __reduce__(self):  # picklable as made (the service computes in worker processes)
        return type(self), (self.field, self.message)


class FixedPointNotFound(RuntimeError):
    """Levenberg–Marquardt did not converge to a fixed point from the given guess."""


class NoGaitFound(FixedPointNotFound):
    """A grid search found no gait at all (:func:`sim_core.section.gait_search.gait_of` without a usable guess).

    Attributes:
        schedule: the controls searched.
        period: the period searched for [jumps].
    """

    def __init__(self, schedule: ControlSchedule, period: int):
        super().__init__(
            f"no period-{period} gait found for controls {schedule.describe()}; give a starting state explicitly"
        )
        self.schedule, self.period = schedule, period

    def __reduce__(self):
        return type(self), (self.schedule, self.period)
