"""Controls per leg and cyclic control schedules (docs/model.md §1, §4).

A jump is set by its leg's touchdown angle ``psi0`` and touchdown length ``zeta0``. A
:class:`ControlSchedule` is the cyclic list of those pairs: one pair is the symmetric case,
two pairs alternate L, R (paper's "alternating controls"), any longer cycle is allowed.
Jump ``k`` (counting from 0) uses ``schedule[k % len(schedule)]``.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np

from sim_core.model.validation import ParameterError, check_range

# Column order of ControlSchedule.as_array(), shared with the compiled kernels.
PSI0_COLUMN = 0
ZETA0_COLUMN = 1


@dataclass(frozen=True, slots=True)
class LegControl:
    """Touchdown controls of one leg.

    Attributes:
        psi0: leg angle at touchdown [rad], measured from the wall normal, positive when the
            body is above the foot; in (0, pi/2).
        zeta0: leg length at touchdown [l0]; in (0, 1). Smaller = more retraction = more
            stored energy ``alpha (1 - zeta0)^2 / 2``.
    """

    psi0: float
    zeta0: float

    def __post_init__(self) -> None:
        if not math.isfinite(self.psi0) or not 0.0 < self.psi0 < math.pi / 2:
            raise ParameterError("psi0", f"must be in (0, 90) degrees, got {math.degrees(self.psi0):g}")
        check_range("zeta0", self.zeta0, 0.0, 1.0)

    @classmethod
    def from_degrees(cls, psi0_deg: float, zeta0: float) -> LegControl:
        """Build from a leg angle in degrees, as UIs and the paper state it."""
        check_range("psi0", psi0_deg, 0.0, 90.0)
        return cls(psi0=math.radians(float(psi0_deg)), zeta0=float(zeta0))

    @property
    def psi0_deg(self) -> float:
        return math.degrees(self.psi0)

    def stored_energy(self, alpha: float) -> float:
        """Spring energy at touchdown, ``alpha (1 - zeta0)^2 / 2`` [m g l0]."""
        return 0.5 * alpha * (1.0 - self.zeta0) ** 2


@dataclass(frozen=True, slots=True)
class ControlSchedule:
    """A cyclic list of leg controls; jump ``k`` uses ``legs[k % len(legs)]``."""

    legs: tuple[LegControl, ...]

    def __post_init__(self) -> None:
        if len(self.legs) == 0:
            raise ParameterError("controls", "need at least one (psi0, zeta0) pair")
        for leg in self.legs:
            if not isinstance(leg, LegControl):
                raise ParameterError("controls", f"expected LegControl, got {type(leg).__name__}")

    @classmethod
    def of(cls, *legs: LegControl) -> ControlSchedule:
        return cls(tuple(legs))

    @classmethod
    def from_degrees(cls, pairs: Iterable[tuple[float, float]]) -> ControlSchedule:
        """``[(psi0_deg, zeta0), ...]`` -> schedule. One pair = symmetric; two = L, R."""
        return cls(tuple(LegControl.from_degrees(psi, zeta) for psi, zeta in pairs))

    def __len__(self) -> int:
        return len(self.legs)

    def __getitem__(self, jump: int) -> LegControl:
        return self.legs[jump % len(self.legs)]

    def as_array(self) -> np.ndarray:
        """Shape ``(len, 2)`` float64: columns ``psi0`` [rad] and ``zeta0`` [l0]."""
        return np.array([[leg.psi0, leg.zeta0] for leg in self.legs], dtype=np.float64)

    def describe(self) -> str:
        """``"30°:0.9, 35°:0.87"`` — the form people read and the CLI accepts (without °)."""
        return ", ".join(f"{leg.psi0_deg:g}°:{leg.zeta0:g}" for leg in self.legs)


OFFSET_LIMITS = {"psi0_offset_deg": 10.0, "zeta0_offset": 0.1}  # |offset| below these: a servo's error, not a new gait


@dataclass(frozen=True, slots=True)
class LegOffsets:
    """What each leg realises beyond what it is commanded: the servos' asymmetry (paper §VI).

    A leg commanded ``(psi0, zeta0)`` touches down at ``(psi0 + psi0_offset_deg, zeta0 + zeta0_offset)``
    of its side. Attributes are ``(left, right)`` pairs, the left leg standing on the left wall;
    angles in degrees, lengths in l0. The default is a perfect robot.
    """

    psi0_offset_deg: tuple[float, float] = (0.0, 0.0)
    zeta0_offset: tuple[float, float] = (0.0, 0.0)

    def __post_init__(self) -> None:
        for field, limit in OFFSET_LIMITS.items():
            pair = getattr(self, field)
            if len(pair) != 2:
                raise ParameterError(field, f"must be two numbers (left, right), got {len(pair)}")
            for side, value in zip(("left", "right"), pair, strict=True):
                check_range(f"{field}.{side}", value, -limit, limit)

    def applied(self, leg: LegControl, right_leg: bool) -> LegControl:
        """``leg`` as the left (``right_leg`` False) or right leg realises it; a :class:`ParameterError`
        when the offset takes it out of the control domain."""
        side = 1 if right_leg else 0
        return LegControl(leg.psi0 + math.radians(self.psi0_offset_deg[side]), leg.zeta0 + self.zeta0_offset[side])

    def to_dict(self) -> dict:
        return {"psi0_offset_deg": list(self.psi0_offset_deg), "zeta0_offset": list(self.zeta0_offset)}


NO_OFFSETS = LegOffsets()
