"""A job's spec as the store keeps it: a versioned record of its own, not the HTTP request.

The request schemas (:mod:`backend.schemas`) decide what a new job may ask for, and they tighten
over time (ranges, the work budget). A stored job was accepted under the rules of its day and
must stay readable whatever the request schema becomes, or a restart could never resume it. So
:func:`spec_of` turns an accepted request into a plain frozen dataclass, :func:`encode` stores it
as ``{"version": 1, "kind": ..., ...}``, and :func:`decode` reads it back — version 1, or the
unversioned request dumps stored before (version 0, the same field names) — without consulting
the request schema at all.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field, fields

from experiments.manifest import json_safe
from sim_core.model.noise import NoiseModel

SPEC_VERSION = 1
_NOISE = NoiseModel()  # the noise's defaults: one home, sim_core.model.noise


@dataclass(frozen=True)
class ModelSpec:
    """The ``paper`` preset with optional nondimensional overrides (None: the preset's)."""

    preset: str = "paper"
    alpha: float | None = None
    d_hat: float | None = None
    c_zeta: float | None = None
    c_psi: float | None = None
    mu: float | None = None


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


@dataclass(frozen=True)
class MJTFSpec:
    zeta0s: tuple[float, ...]
    model: ModelSpec = field(default_factory=ModelSpec)
    psi0_deg: float = 30.0
    trials: int = 8
    cap: int = 1000
    seed: int = 0
    noise: NoiseSpec = field(default_factory=NoiseSpec)
    guess: StateSpec | None = None
    kind: str = "mjtf"


@dataclass(frozen=True)
class SweepSpec:
    model: ModelSpec = field(default_factory=ModelSpec)
    psi0_deg: float = 30.0
    zeta0_low: float = 0.8
    zeta0_high: float = 0.97
    steps: int = 30
    basin_grid: int = 40
    basin_jumps: int = 60
    basin_jump_limit: int | None = None
    guess: StateSpec | None = None
    kind: str = "sweep"


@dataclass(frozen=True)
class BasinSpec:
    controls: tuple[LegSpec, ...]
    model: ModelSpec = field(default_factory=ModelSpec)
    period: int | None = None
    guess: StateSpec | None = None
    grid: int = 100
    jumps: int = 60
    jump_limit: int | None = None
    tolerance: float = 0.02
    kind: str = "basin"


@dataclass(frozen=True)
class GaitSearchSpec:
    controls: tuple[LegSpec, ...]
    model: ModelSpec = field(default_factory=ModelSpec)
    period: int | None = None
    grid: int = 6
    kind: str = "gaits"


@dataclass(frozen=True)
class ControlStudySpec:
    controllers: tuple[str, ...] = ("pid", "pid-pitch", "lqr", "deadbeat")
    model: ModelSpec = field(default_factory=ModelSpec)
    target_m: float = 0.55
    psi0_deg: float = 35.0
    start_zeta0: float = 0.9
    jumps: int = 400
    seeds: int = 200
    seed0: int = 0
    noise: NoiseSpec = field(default_factory=NoiseSpec)
    kind: str = "control-study"


@dataclass(frozen=True)
class MfptSpec:
    model: ModelSpec = field(default_factory=ModelSpec)
    psi0_deg: float = 30.0
    zeta0: float = 0.9
    start: StateSpec | None = None
    guess: StateSpec | None = None
    noise: NoiseSpec = field(default_factory=NoiseSpec)
    grid: int = 30
    pitch_spacing: float = 0.5
    kind: str = "mfpt"


@dataclass(frozen=True)
class LoopMfptSpec:
    controller: str = "lqr"
    model: ModelSpec = field(default_factory=ModelSpec)
    target_m: float = 0.55
    psi0_deg: float = 35.0
    start_zeta0: float = 0.9
    noise: NoiseSpec = field(default_factory=lambda: NoiseSpec(pitch_drift_deg=0.0))
    replicas: int = 100
    runs: int = 64
    seed: int = 0
    kind: str = "loop-mfpt"


@dataclass(frozen=True)
class ViabilitySpec:
    model: ModelSpec = field(default_factory=ModelSpec)
    states: int = 40
    actions: int = 16
    psi0_low_deg: float = 15.0
    psi0_high_deg: float = 55.0
    zeta0_low: float = 0.7
    zeta0_high: float = 0.98
    kind: str = "viability"


JobSpec = MJTFSpec | SweepSpec | BasinSpec | GaitSearchSpec | ControlStudySpec | MfptSpec | LoopMfptSpec | ViabilitySpec
SPECS: dict[str, type] = {"mjtf": MJTFSpec, "sweep": SweepSpec, "basin": BasinSpec, "gaits": GaitSearchSpec,
                          "control-study": ControlStudySpec, "mfpt": MfptSpec, "loop-mfpt": LoopMfptSpec,
                          "viability": ViabilitySpec}  # fmt: skip
_PARTS = {"model": ModelSpec, "noise": NoiseSpec, "guess": StateSpec, "start": StateSpec}


class UnreadableSpec(ValueError):
    """A stored spec of a version or kind this code does not know."""


def spec_of(body) -> JobSpec:
    """An accepted job request (any of ``schemas.JOB_KINDS``) as the spec the store keeps."""
    return decode(body.model_dump(mode="json"))


def encode(spec: JobSpec) -> dict:
    """The spec as the store's JSON (plain lists and dicts)."""
    return {"version": SPEC_VERSION, **json_safe(asdict(spec))}


def decode(stored: dict) -> JobSpec:
    """A stored spec, version 1 or unversioned (0); fields it does not use (``experiment_id``)
    are left out, missing ones take the defaults of their day."""
    version = stored.get("version", 0)
    if version not in (0, SPEC_VERSION):
        raise UnreadableSpec(f"job spec version {version} is newer than this code (it reads up to {SPEC_VERSION})")
    kind = stored.get("kind", "mjtf")
    if kind not in SPECS:
        raise UnreadableSpec(f"unknown job kind {kind!r}")
    cls = SPECS[kind]
    values = {}
    for spec_field in fields(cls):
        if spec_field.name not in stored:
            continue
        value = stored[spec_field.name]
        if spec_field.name in _PARTS and value is not None:
            value = _PARTS[spec_field.name](**value)
        elif spec_field.name == "controls":
            value = tuple(LegSpec(**leg) for leg in value)
        elif spec_field.name in ("zeta0s", "controllers"):
            value = tuple(value)
        values[spec_field.name] = value
    return cls(**values)
