"""Servo limits: every leg command is checked against them on the PC and again on the robot."""

from __future__ import annotations

import math
from dataclasses import dataclass

from backend.robot.messages import on_the_wire
from sim_core.model.validation import ParameterError, check_range


@dataclass(frozen=True)
class ServoLimits:
    """What the leg servos can reach: leg angle [degrees] and length [l0] at touchdown."""

    psi0_deg: tuple[float, float] = (10.0, 60.0)
    zeta0: tuple[float, float] = (0.75, 0.98)

    def __post_init__(self) -> None:
        for name, (low, high), bound in (("psi0_deg", self.psi0_deg, (0.0, 90.0)), ("zeta0", self.zeta0, (0.0, 1.0))):
            check_range(f"limits.{name}", low, *bound)
            check_range(f"limits.{name}", high, *bound)
            if not low < high:
                raise ParameterError(f"limits.{name}", f"must be an interval low < high, got [{low:g}, {high:g}]")

    def check(self, psi0_deg: float, zeta0: float) -> None:
        """Raise :class:`ParameterError` naming the field and the servo range if a command is outside
        it, as SET_LEG carries it (0.01°, 0.0001 l0): a law's angle clipped to 30° in radians comes
        back as 29.999999999999996° and goes out as 30.00°, within a range from 30°."""
        psi0_deg, zeta0 = on_the_wire(psi0_deg, zeta0)
        check_range("psi0_deg", psi0_deg, *self.psi0_deg, low_open=False, high_open=False)
        check_range("zeta0", zeta0, *self.zeta0, low_open=False, high_open=False)

    def held(self, psi0: float, zeta0: float) -> tuple[tuple[float, float], bool]:
        """A law's command ``(psi0 [rad], zeta0)`` held to the servos' range, and whether it had to be."""
        low, high = (math.radians(bound) for bound in self.psi0_deg)
        held = (min(max(psi0, low), high), min(max(zeta0, self.zeta0[0]), self.zeta0[1]))
        return held, held != (psi0, zeta0)

    def allows(self, psi0_deg: float, zeta0: float) -> bool:
        try:
            self.check(psi0_deg, zeta0)
        except ParameterError:
            return False
        return True
