"""The foot-placement law's settings: the next leg chosen on the model so that its foot lands where
a plan aims it, with margins (:mod:`sim_core.control.placement` computes it;
:mod:`sim_core.planning.follow` follows a plan with it)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from sim_core.control.height_controller import HeightController
from sim_core.control.laws.common import PSI0_RANGE_DEG, check_interval
from sim_core.model.validation import check_range


@dataclass(frozen=True)
class PlacementSettings:
    """How the law chooses (docs/analyses.md, "Foot placement"): the leg's range relative to the
    body, the margins a landing keeps — ``end_margin`` [l0] along the foothold from either end (a
    quarter of a shorter foothold), ``cone_margin_deg`` inside its friction cone (half the cone's
    at most) — and the cost's scales: how far from the aimed foot [l0], velocity [sqrt(g l0)],
    angle [deg] and length [l0] weigh alike."""

    zeta0_range: tuple[float, float] = (HeightController.zeta0_min, 0.96)
    psi0_range_deg: tuple[float, float] = PSI0_RANGE_DEG
    end_margin: float = 0.05
    cone_margin_deg: float = 3.0
    position_scale: float = 0.05
    velocity_scale: float = 0.1
    psi0_scale_deg: float = 10.0
    zeta0_scale: float = 0.1

    def __post_init__(self) -> None:
        check_interval("zeta0_range", self.zeta0_range, 1.0)
        check_interval("psi0_range_deg", self.psi0_range_deg, 90.0)
        check_range("end_margin", self.end_margin, 0.0, 1.0)
        check_range("cone_margin_deg", self.cone_margin_deg, 0.0, 45.0)
        for field in ("position_scale", "velocity_scale", "psi0_scale_deg", "zeta0_scale"):
            check_range(field, getattr(self, field), 0.0, 1e3)

    def array(self) -> np.ndarray:
        """The kernel's settings (:mod:`sim_core.control.placement`'s layout), angles in rad."""
        return np.array([
            *(math.radians(value) for value in self.psi0_range_deg), *self.zeta0_range, self.end_margin,
            math.radians(self.cone_margin_deg), self.position_scale, self.velocity_scale,
            math.radians(self.psi0_scale_deg), self.zeta0_scale,
        ])  # fmt: skip
