"""Experiments: a named, described, tagged group of runs and jobs."""

from __future__ import annotations

import datetime
from typing import Annotated

from pydantic import BaseModel, Field

from backend.schemas.common import Notes, Page, Strict, Tags

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
