"""What every resource's bodies share: the strict base of a request, the leg, model and state
inputs, the limits, record references and the page of a list."""

from __future__ import annotations

import datetime
import enum
import math
from typing import Annotated, Generic, Literal, TypeVar

from pydantic import BaseModel, BeforeValidator, ConfigDict, Field

from sim_core.climb.records import CHUTE_TOP, FLOOR
from sim_core.control.laws import PSI0_RANGE_DEG
from sim_core.control.registry import NAMES
from sim_core.model.params import ModelParams
from sim_core.model.presets import preset_model

ControllerKind = enum.StrEnum("ControllerKind", {name.replace("-", "_").upper(): name for name in NAMES})
ControllerKind.__doc__ = "A closed-loop law (the registry, sim_core.control.laws.LAWS)."


# A leg angle in (0, 90) degrees, a hair taken off the low end: the kernels take radians, and an
# angle a hair above 0 (5e-324 degrees) would be 0 there (every double below 90 stays below pi/2).
# The schema says the bounds it holds to, so every value the OpenAPI document allows is accepted.
PSI0_HAIR_DEG = 1e-9
Psi0Deg = Annotated[
    float,
    Field(ge=PSI0_HAIR_DEG, lt=90.0, description=f"leg angle at touchdown [degrees], in [{PSI0_HAIR_DEG:g}, 90)"),
]


def _iso_8601(value: object) -> object:
    # Pydantic alone takes a number as seconds since 1970: "0.5" would be a date.
    if isinstance(value, str):
        try:
            return datetime.datetime.fromisoformat(value)
        except ValueError:
            example = "e.g. 2026-12-03 or 2026-12-03T14:00:00Z"
            raise ValueError(f"must be an ISO 8601 date or time, {example}, got {value!r}") from None
    return value


IsoDateTime = Annotated[datetime.datetime, BeforeValidator(_iso_8601)]
Zeta0 = Annotated[float, Field(gt=0.0, lt=1.0, description="leg length at touchdown [l0], in (0, 1)")]
# A controller's climb (the control study's and a controller's MFPT): the height it holds, its leg angle.
TargetHeightM = Annotated[
    float, Field(gt=FLOOR, le=CHUTE_TOP, description="height to hold [m], above the floor, within the chute")
]
NominalPsi0Deg = Annotated[
    float, Field(ge=PSI0_RANGE_DEG[0], le=PSI0_RANGE_DEG[1], description="nominal leg angle [deg]")
]
Label = Annotated[str, Field(min_length=1, max_length=64, pattern=r"^[\w.:/-]+$")]  # a tag
Tags = Annotated[list[Label], Field(max_length=32)]
Notes = Annotated[str, Field(max_length=100_000)]

MAX_JUMPS = 10_000
MAX_FRICTION = 100.0  # a friction coefficient past any real wall's (rubber on rock is about 1)
MAX_TRIALS = 100_000
MAX_LEVELS = 100
MAX_PATH_SAMPLES = 100_000
MAX_PAGE = 500  # items in one page of a list
MAX_ID = 2**31 - 1  # integer keys: the smallest range among the supported databases (PostgreSQL)
RecordRef = Annotated[int, Field(ge=1, le=MAX_ID)]
Item = TypeVar("Item")  # what a Page lists


class Strict(BaseModel):
    """Every request body: unknown fields refused; NaN, ±Infinity (and 1e309, which JSON parsing
    makes infinite) refused in every float field; a string with a lone surrogate (``"\\ud800"``)
    is refused by pydantic itself (``string_unicode``) — each a 422 naming the field."""

    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)


class LegIn(Strict):
    psi0_deg: Psi0Deg
    zeta0: Zeta0


class ModelIn(Strict):
    """A preset — ``paper``, or a calibration stored by name (docs/calibration.md) — with optional
    nondimensional overrides (docs/model.md §1)."""

    preset: str = Field(
        "paper", min_length=1, max_length=64, pattern=r"^[A-Za-z0-9][A-Za-z0-9_.-]{0,63}$",
        description="paper, or a stored calibration's name (GET /api/v1/calibrations)",
    )  # fmt: skip
    alpha: Annotated[float, Field(gt=0.0, le=1e4)] | None = None
    d_hat: Annotated[float, Field(gt=0.0, le=100.0)] | None = None
    c_zeta: Annotated[float, Field(ge=0.0, le=1e3)] | None = None
    c_psi: Annotated[float, Field(ge=0.0, le=1e3)] | None = None
    mu: Annotated[float, Field(gt=0.0, le=MAX_FRICTION)] | None = Field(
        None, description=f"friction coefficient, in (0, {MAX_FRICTION:g}]; omit for the preset (no slip)"
    )

    def params(self) -> ModelParams:
        """The model this asks for: its preset with its overrides. A stored preset is resolved to its
        base before a request gets here (backend.services.presets.with_preset_resolved)."""
        overrides = self.model_dump(exclude={"preset"})
        return preset_model(self.preset, field="model.preset", **overrides)


class StateIn(Strict):
    xdot: Annotated[float, Field(lt=0.0, ge=-100.0, description="section xdot [sqrt(g l0)], < 0")]
    ydot: Annotated[float, Field(ge=-100.0, le=100.0, description="section ydot [sqrt(g l0)]")]


class Health(BaseModel):
    status: Literal["ok", "warming"] = Field(
        description="warming: just started, the workers that answer reads and simulations are still loading"
        " (a request now waits for them); ok: they are ready"
    )
    warming: list[str] = Field(
        default_factory=list,
        description="the worker pools still loading: reads (the run list, exports), quick (simulations,"
        " POST /runs), jobs (every job kind's kernels: jobs wait in the queue meanwhile, status stays ok)",
    )
    database: str = Field(description="the database's dialect: sqlite or postgresql")
    code_version: str
    notices: list[str] = Field(
        default_factory=list, description="what the service waits for, e.g. disk space to store a job's trials"
    )


class TokenAccepted(BaseModel):
    """Whose the bearer token is, and what it may do."""

    accepted: Literal[True]
    name: str = Field(description="the person the token signs in (lab: the service's own token, api_token)")
    access: Literal["write", "read"] = Field(description="write: reads and changes; read: reads only")


class Page(BaseModel, Generic[Item]):
    """One page of a list, newest first unless sorted otherwise."""

    items: list[Item]
    next_cursor: int | None = Field(None, description="pass as ?cursor= for the next page; null at the end")
    total: int | None = Field(None, description="how many items match, over every page (null: not counted)")


def finite_or_none(value: float) -> float | None:
    return value if math.isfinite(value) else None
