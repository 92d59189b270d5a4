"""A job's spec as the store keeps it: a versioned record of its own, not the HTTP request.

The request schemas (each kind's module) decide what a new job may ask for, and they tighten
over time (ranges, the work budget). A stored job was accepted under the rules of its day and
must stay readable whatever the request schema becomes, or a restart could never resume it. So
:func:`spec_of` (:mod:`backend.jobs`) turns an accepted request into its kind's plain frozen
dataclass, :func:`encode` stores it as ``{"version": 1, "kind": ..., ...}``, and
:func:`backend.jobs.decode` reads it back — version 1, or the unversioned request dumps stored
before (version 0, the same field names) — with :func:`read_fields`, without consulting the
request schema at all. Here: the parts every kind's spec shares.
"""

from __future__ import annotations

import functools
import types
import typing
from dataclasses import asdict, dataclass, fields, is_dataclass

from experiments.manifest import json_safe
from sim_core.model.noise import NoiseModel
from sim_core.model.params import ModelParams
from sim_core.model.presets import preset_model

SPEC_VERSION = 1
_NOISE = NoiseModel()  # the noise's defaults: one home, sim_core.model.noise


class UnreadableSpec(ValueError):
    """A stored spec of a version or kind this code does not know."""


@dataclass(frozen=True)
class ModelSpec:
    """The ``paper`` preset with optional nondimensional overrides (None: the preset's)."""

    preset: str = "paper"
    alpha: float | None = None
    d_hat: float | None = None
    c_zeta: float | None = None
    c_psi: float | None = None
    mu: float | None = None

    def params(self) -> ModelParams:
        """The model the job runs: its preset (a stored one was resolved to its base when the job
        was accepted) with its overrides."""
        overrides = {name: value for name, value in asdict(self).items() if name != "preset"}
        return preset_model(self.preset, field="model.preset", **overrides)


@dataclass(frozen=True)
class LegSpec:
    psi0_deg: float
    zeta0: float


@dataclass(frozen=True)
class StateSpec:
    xdot: float
    ydot: float


@dataclass(frozen=True)
class NoiseSpec:
    """:class:`~sim_core.model.noise.NoiseModel`'s fields as stored, not validated here (the runner's
    ``NoiseModel`` is): a spec stays readable whatever the ranges become."""

    psi0_deg: float = _NOISE.psi0_deg
    zeta0: float = _NOISE.zeta0
    velocity: float = _NOISE.velocity
    pitch_drift_deg: float = _NOISE.pitch_drift_deg
    asymmetry_psi0_deg: float = _NOISE.asymmetry_psi0_deg
    asymmetry_zeta0: float = _NOISE.asymmetry_zeta0

    def model(self) -> NoiseModel:
        """The noise as sim_core runs it (a ParameterError naming the field if out of range)."""
        return NoiseModel(**asdict(self))


_TUPLES = ("zeta0s", "controllers", "psi0_range", "zeta0_range")  # lists stored, tuples in the frozen spec


def encode(spec) -> dict:
    """The spec as the store's JSON (plain lists and dicts)."""
    return {"version": SPEC_VERSION, **json_safe(asdict(spec))}


@functools.cache
def _part_of(cls: type, name: str) -> type | None:
    """The dataclass a spec's field holds (``model: ModelSpec``, ``guess: StateSpec | None``: StateSpec), if any:
    read from the spec's own annotations, so a kind's part of its own needs no list here."""
    hint = typing.get_type_hints(cls).get(name)
    options = typing.get_args(hint) if isinstance(hint, types.UnionType) else (hint,)  # not tuple[LegSpec, ...]
    return next((option for option in options if is_dataclass(option)), None)


def read_fields(cls: type, stored: dict):
    """``cls`` (a kind's spec) from its stored JSON: fields it does not use (``experiment_id``) are
    left out, missing ones take the defaults of their day."""
    values = {}
    for spec_field in fields(cls):
        if spec_field.name not in stored:
            continue
        value = stored[spec_field.name]
        part = _part_of(cls, spec_field.name)
        if part is not None and value is not None:
            value = part(**value)
        elif spec_field.name == "controls":
            value = tuple(LegSpec(**leg) for leg in value)
        elif spec_field.name in _TUPLES:
            value = tuple(value)
        values[spec_field.name] = value
    return cls(**values)
