"""Experiments: a named, described, tagged group of runs and jobs."""

from __future__ import annotations

import datetime
from typing import Annotated

from pydantic import BaseModel, Field

from backend.schemas.common import Notes, Page, Strict, Tags
from backend.schemas.jobs import JobOut
from backend.schemas.runs import RunGroup

MAX_SUMMARY_JOBS = 200  # an experiment page lists its newest jobs, up to this
Name = Annotated[str, Field(min_length=1, max_length=200)]
Description = Annotated[str, Field(max_length=10_000)]


class ExperimentBase(BaseModel):
    name: Name
    description: Description = ""
    notes: Notes = ""
    tags: Tags = []


class ExperimentCreate(ExperimentBase, Strict):
    pass


class ExperimentUpdate(Strict):
    """Fields left out (or null) stay as they are."""

    name: Name | None = None
    description: Description | None = None
    notes: Notes | None = None
    tags: Tags | None = None


class ExperimentOut(ExperimentBase):
    # Outputs are not held to today's input ranges: a record stored under older limits still reads.
    name: str
    description: str
    notes: str
    tags: list[str]
    id: int
    created_at: datetime.datetime
    updated_at: datetime.datetime
    runs: int = Field(description="how many runs it holds")


ExperimentPage = Page[ExperimentOut]


class ExperimentSummary(BaseModel):
    """An experiment's page: the experiment (with its notes), its runs' outcomes over every run and
    by kind — mean, std, range and 95% interval of the climb and jumps completed — how its runs
    ended, and its jobs, newest first."""

    experiment: ExperimentOut
    runs: int = Field(description="how many runs it holds")
    outcomes: RunGroup | None = Field(description="over all its runs (key: its id); null when it has none")
    by_kind: list[RunGroup] = Field(description="the same per kind of run (key: sim, robot, replay)")
    statuses: dict[str, int] = Field(description="its runs by status")
    end_reasons: dict[str, int] = Field(description="its robot runs by how they ended, as recorded")
    loops: dict[str, int] = Field(description="its runs by loop: open, closed")
    jobs: list[JobOut] = Field(description=f"its jobs, newest first (at most {MAX_SUMMARY_JOBS})")
    jobs_total: int = Field(description="how many jobs it holds")
