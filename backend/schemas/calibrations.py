"""Calibrations: a request to fit the model to robot runs, and the fitted preset that comes back
(docs/calibration.md). Standard errors are null where a parameter is not identifiable."""

from __future__ import annotations

import datetime
from typing import Annotated, Literal

from pydantic import BaseModel, Field

from backend.schemas.common import MAX_ID, Strict

PRESET_PATTERN = r"^[A-Za-z0-9][A-Za-z0-9_.-]{0,63}$"  # a stored preset's name
PresetName = Annotated[str, Field(min_length=1, max_length=64, pattern=PRESET_PATTERN)]
Pair = Annotated[list[float], Field(min_length=2, max_length=2)]
MaybePair = Annotated[list[float | None], Field(min_length=2, max_length=2)]


class CalibrationCreate(Strict):
    runs: Annotated[list[Annotated[int, Field(ge=1, le=MAX_ID)]], Field(min_length=1, max_length=100)] = Field(
        description="robot or replay runs to fit"
    )
    name: PresetName = Field(description="the preset to store; not a built-in one's name")
    preset: Literal["paper"] = Field("paper", description="the built-in preset to start from")


class CalibratedParams(BaseModel):
    alpha: float
    c_zeta: float
    c_psi: float
    psi0_offset_deg: Pair = Field(description="[left, right] [deg]")
    zeta0_offset: Pair = Field(description="[left, right] [l0]")


class CalibratedStderr(BaseModel):
    alpha: float | None
    c_zeta: float | None
    c_psi: float | None
    psi0_offset_deg: MaybePair
    zeta0_offset: MaybePair


class ResidualChannel(BaseModel):
    unit: str
    rms_before: float | None
    rms_after: float | None


class PresetProvenance(BaseModel):
    name: str
    base: str
    runs: list[int]
    created_at: datetime.datetime
    code_version: str
    physical: dict[str, float | None] = Field(description="the fitted robot in SI (PhysicalParams)")


class CalibrationOut(BaseModel):
    params: CalibratedParams
    stderr: CalibratedStderr
    parameters: list[str] = Field(description="the correlation matrix's row and column order")
    correlation: list[list[float | None]]
    unidentifiable: list[str] = Field(description="parameters the runs do not constrain at all")
    confounded: list[tuple[str, str, float]] = Field(
        description="pairs of parameters correlated beyond ±0.95: the runs fix a combination better than either"
    )
    touchdowns_used: int = Field(description="touchdown pairs the model predicted")
    rms_residual_before: float | None = Field(description="one-jump section-state error [sqrt(g l0)], base model")
    rms_residual_after: float | None = Field(description="the same with the fitted model")
    residuals: dict[str, ResidualChannel]
    noise: dict[str, float | None] = Field(description="residual scatter per channel after the fit")
    failed_predictions: int
    preset: PresetProvenance


class CalibrationList(BaseModel):
    items: list[CalibrationOut]


class Channels(BaseModel):
    xdot: float | None = Field(description="[sqrt(g l0)]")
    ydot: float | None = Field(description="[sqrt(g l0)]")
    rise: float | None = Field(description="foot height gained since the touchdown before [l0]")


class TouchdownPrediction(BaseModel):
    index: int = Field(description="the touchdown's number in the run (0-based)")
    time: float = Field(description="[s], the tracker's clock")
    wall: str
    measured: Channels
    paper: Channels = Field(description="predicted by the base model from the touchdown before")
    paper_residual: Channels
    calibrated: Channels | None = None
    calibrated_residual: Channels | None = None


class PredictedIn(BaseModel):
    id: int
    name: str


class TouchdownComparison(BaseModel):
    run_id: int
    base: str
    preset: str | None
    world: PredictedIn | None = Field(
        None, description="the stored world the run climbed, each prediction a jump in it; null: parallel walls"
    )
    touchdowns: list[TouchdownPrediction]
    rms: dict[str, Channels] = Field(description="RMS residual per model")
