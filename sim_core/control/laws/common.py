"""What every control law shares: the leg's range, the size of a law's memory, what a law is
designed for (:class:`DesignRequest`), and the interval check."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

from sim_core.model.validation import ParameterError, check_range

if TYPE_CHECKING:
    from sim_core.control.height_controller import HeightController
    from sim_core.model.params import ModelParams

# The leg angle's range relative to the body [deg]: the robot's angle servos (backend/robot/limits.py).
PSI0_RANGE_DEG = (10.0, 60.0)
MEMORY_SIZE = 2  # a law's state between touchdowns: the PID's integral and previous error; else the last command
DEADBEAT_CLIMB_PER_JUMP = 0.5  # [l0]: a 2 l0 climb in about 6 jumps


@dataclass(frozen=True)
class DesignRequest:
    """What a front end asks of a law: hold ``height.target`` [l0] on ``model`` about the gait of
    jumping in place at ``psi0_deg`` with ``height.zeta0_hover``, the leg length within the height
    loop's range, the leg angle within ``psi0_range_deg`` (the servos'); the PIDs take
    ``height``'s gains, the deadbeat ``climb_per_jump`` [l0]. Each law reads what it needs."""

    model: ModelParams
    height: HeightController
    psi0_deg: float
    psi0_range_deg: tuple[float, float] = PSI0_RANGE_DEG
    climb_per_jump: float = DEADBEAT_CLIMB_PER_JUMP

    @property
    def zeta0_range(self) -> tuple[float, float]:
        return (self.height.zeta0_min, self.height.zeta0_max)


def check_interval(field: str, interval: tuple[float, float], bound: float) -> None:
    """A ParameterError naming ``field`` unless ``interval`` is ``low < high`` within ``[0, bound]``."""
    low, high = interval
    check_range(field, low, 0.0, bound)
    check_range(field, high, 0.0, bound)
    if not low < high:
        raise ParameterError(field, f"must be an interval (low < high), got [{low:g}, {high:g}]")
