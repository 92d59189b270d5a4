"""The height controller's parameters: a PID closed once per jump on the touchdown height (docs/model.md §5.2).

The control law and the loop are :mod:`sim_core.control.closed_loop` (compiled); this module is the
controller as data, numpy-free and kernel-free, so options and forms read its defaults (the
gains a scan chose) without loading the kernels.
"""

from __future__ import annotations

from dataclasses import dataclass

from sim_core.model.validation import ParameterError, check_range


@dataclass(frozen=True)
class HeightController:
    """PID on the touchdown height error; gains in zeta0 per l0 of error (per jump for ki, kd)."""

    target: float  # [l0]
    zeta0_hover: float  # feed-forward: zeta0 of jumping in place
    # Defaults from a gain scan at psi0 = 35° (docs/analyses.md): settles in ~30 jumps without
    # overshoot. The integral is off by default: the hover feed-forward already removes the
    # model's steady error, and any ki > 0 we scanned settled later; raise it against bias
    # such as leg asymmetry.
    kp: float = 0.04
    ki: float = 0.0
    kd: float = 0.02
    zeta0_min: float = 0.80
    zeta0_max: float = 0.98

    def __post_init__(self) -> None:
        check_range("target", self.target, 0.0, 1e4)
        for name in ("kp", "ki", "kd"):
            check_range(name, getattr(self, name), 0.0, 10.0, low_open=False)
        check_range("zeta0_min", self.zeta0_min, 0.0, 1.0)
        check_range("zeta0_max", self.zeta0_max, 0.0, 1.0)
        if not self.zeta0_min < self.zeta0_max:
            raise ParameterError("zeta0_max", f"must exceed zeta0_min = {self.zeta0_min:g}, got {self.zeta0_max:g}")
        check_range("zeta0_hover", self.zeta0_hover, self.zeta0_min, self.zeta0_max, low_open=False, high_open=False)
