"""Model parameters: dimensional (SI) and nondimensional, with conversion both ways (docs/model.md §1).

The simulation runs in nondimensional units: length ``l0``, time ``sqrt(l0/g)``, velocity
``sqrt(g l0)``, energy ``m g l0``. :class:`PhysicalParams` holds the robot as measured;
:class:`ModelParams` holds the five numbers the dynamics depend on. Both are frozen and
validated on construction; vary one with :func:`dataclasses.replace`.

>>> from sim_core.model.presets import get_preset
>>> model = get_preset("paper").to_model()
>>> round(model.alpha, 1), round(model.d_hat, 2)
(77.6, 2.42)
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple

from sim_core.model.validation import check_range


class ModelRecord(NamedTuple):
    """:class:`ModelParams` as the compiled kernels take it (:meth:`ModelParams.record`): one typed
    argument, read by field (``model.alpha``), so a new parameter is added here and in the dataclass
    alone, not to every kernel's argument list. numba types it as a named tuple of five float64.
    Fields, units and order as :class:`ModelParams`'s (tests/sim_core/model/test_params.py checks it).

    A ``parallel`` kernel takes a record as an argument; one it built itself and used in a
    ``prange`` loop fails to compile (numba 0.68 cannot name the type in the loop's generated
    function), so records are built outside such kernels or in the kernels they call.
    """

    alpha: float
    d_hat: float
    c_zeta: float
    c_psi: float
    mu: float


@dataclass(frozen=True, slots=True)
class ModelParams:
    """Nondimensional ParkourBot model (docs/model.md §1).

    Attributes:
        alpha: ``k l0 / (m g)``, spring force at full compression over weight, > 0.
        d_hat: ``d / l0``, wall distance in leg lengths, > 0.
        c_zeta: ``c_zeta sqrt(l0/g) / m``, radial (leg) damping, >= 0.
        c_psi: ``c_psi sqrt(l0/g) / m``, pivot damping, >= 0 (the paper's table reading).
        mu: wall friction coefficient, > 0; ``inf`` disables slipping.
    """

    alpha: float
    d_hat: float
    c_zeta: float = 0.0
    c_psi: float = 0.0
    mu: float = math.inf

    def __post_init__(self) -> None:
        check_range("alpha", self.alpha, 0.0)
        check_range("d_hat", self.d_hat, 0.0)
        _check_damping_and_friction(self)

    def record(self) -> ModelRecord:
        """The parameters as the compiled kernels take them. Each is a Python float, so an ``int``
        given here does not compile a second specialisation of every kernel."""
        return ModelRecord._make(float(getattr(self, name)) for name in ModelRecord._fields)


@dataclass(frozen=True, slots=True)
class Scales:
    """Units of the nondimensional model in SI: multiply a nondimensional value by these."""

    length: float  # l0 [m]
    time: float  # sqrt(l0 / g) [s]
    velocity: float  # sqrt(g l0) [m/s]
    energy: float  # m g l0 [J]


@dataclass(frozen=True, slots=True)
class PhysicalParams:
    """ParkourBot physical parameters in SI units (paper Table I, docs/model.md §1).

    Attributes:
        mass: body mass m [kg].
        leg_length: leg rest length l0 [m].
        stiffness: leg spring stiffness k [N/m].
        wall_distance: distance between the walls d [m].
        gravity: effective gravity g [m/s^2] (reduced on the tilted air table).
        c_zeta: radial damping [N s/m].
        c_psi: pivot damping [N s], normalised like c_zeta (docs/model.md §1).
        mu: foot-wall friction coefficient [-]; ``inf`` disables slipping.
    """

    mass: float
    leg_length: float
    stiffness: float
    wall_distance: float
    gravity: float
    c_zeta: float = 0.0
    c_psi: float = 0.0
    mu: float = math.inf

    def __post_init__(self) -> None:
        for field in ("mass", "leg_length", "stiffness", "wall_distance", "gravity"):
            check_range(field, getattr(self, field), 0.0)
        _check_damping_and_friction(self)

    @property
    def scales(self) -> Scales:
        time = math.sqrt(self.leg_length / self.gravity)
        return Scales(
            length=self.leg_length,
            time=time,
            velocity=math.sqrt(self.gravity * self.leg_length),
            energy=self.mass * self.gravity * self.leg_length,
        )

    def to_model(self) -> ModelParams:
        """The nondimensional parameters of this robot."""
        time = self.scales.time
        return ModelParams(
            alpha=self.stiffness * self.leg_length / (self.mass * self.gravity),
            d_hat=self.wall_distance / self.leg_length,
            c_zeta=self.c_zeta * time / self.mass,
            c_psi=self.c_psi * time / self.mass,
            mu=self.mu,
        )

    @classmethod
    def from_model(cls, model: ModelParams, *, mass: float, leg_length: float, gravity: float) -> PhysicalParams:
        """The robot with ``model``'s dynamics at the given mass [kg], l0 [m] and g [m/s^2]."""
        check_range("mass", mass, 0.0)
        check_range("leg_length", leg_length, 0.0)
        check_range("gravity", gravity, 0.0)
        time = math.sqrt(leg_length / gravity)
        return cls(
            mass=mass,
            leg_length=leg_length,
            stiffness=model.alpha * mass * gravity / leg_length,
            wall_distance=model.d_hat * leg_length,
            gravity=gravity,
            c_zeta=model.c_zeta * mass / time,
            c_psi=model.c_psi * mass / time,
            mu=model.mu,
        )


def _check_damping_and_friction(params: ModelParams | PhysicalParams) -> None:
    """What both parameter sets require of the same fields: damping >= 0, friction > 0 (inf: no slip)."""
    check_range("c_zeta", params.c_zeta, 0.0, low_open=False)
    check_range("c_psi", params.c_psi, 0.0, low_open=False)
    check_range("mu", params.mu, 0.0, math.inf, high_open=False, allow_inf=True)
