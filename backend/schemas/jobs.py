"""Batch jobs as a client reads them: a job's state, the job and its results. What a client may ask
for, kind by kind, is each kind's module in :mod:`backend.jobs`."""

from __future__ import annotations

import datetime
import enum

from pydantic import BaseModel, Field

from backend.schemas.common import (
    Page,
)

CLIENT_PATTERN = r"^[\w.:@/-]{1,64}$"  # the X-Parkour-Client header: the tool that submits (a label)


class JobState(enum.StrEnum):
    QUEUED = "queued"
    RUNNING = "running"
    CANCELLING = "cancelling"
    CANCELLED = "cancelled"
    DONE = "done"
    FAILED = "failed"


class JobOut(BaseModel):
    id: int
    experiment_id: int | None
    world_id: int | None = Field(None, description="the stored world it works in; null: parallel walls")
    kind: str
    state: JobState
    total: int
    completed: int
    progress: float
    error: str | None
    spec: dict
    created_at: datetime.datetime
    started_at: datetime.datetime | None
    finished_at: datetime.datetime | None
    submitted_by: str | None = Field(
        None, description="who submitted it: the token's person (null: a job stored before people had names)"
    )
    submitted_via: str | None = Field(None, description="the tool it came through: its X-Parkour-Client header")
    queue_position: int | None = Field(None, description="1: runs next; null when not queued")
    eta_s: float | None = Field(
        None, description="seconds until it should end: its time and the jobs' ahead as expected on this machine"
    )
    eta_max_s: float | None = Field(
        None, description="seconds until it ends at the latest (its work and the work ahead at their worst)"
    )


JobPage = Page[JobOut]


class MJTFLevelOut(BaseModel):
    zeta0: float
    trials: int
    mean: float
    std: float
    outcomes: dict[str, int]


class JobResults(BaseModel):
    job: JobOut
    partial: bool = Field(description="not done (queued, running, cancelled or failed): not every trial is in")
    levels: list[MJTFLevelOut] | None = Field(None, description="MJTF jobs: the energy levels with trials so far")
    missing_zeta0s: list[float] | None = Field(None, description="MJTF jobs: the levels without a trial yet")
    result: dict | None = Field(None, description="other jobs: the study's result, once done")
