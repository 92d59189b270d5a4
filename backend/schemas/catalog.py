"""What this service offers, for choosers (the panel's lists, a script's menus): its registries
read as data — the controllers (:data:`sim_core.control.registry.LAWS`) and the job kinds
(:data:`backend.jobs.KINDS`)."""

from __future__ import annotations

from pydantic import BaseModel, Field


class ControllerOut(BaseModel):
    name: str = Field(description="what requests name it by (a control study's controllers, a loop's controller)")
    summary: str = Field(description="one line for a chooser")
    sets_leg_angle: bool = Field(description="false: the law leaves the leg angle where the leg holds it")


class JobKindOut(BaseModel):
    name: str = Field(description="a job request's kind")
    title: str = Field(description="one line for a chooser")
    request: str = Field(description="its request body's schema in the OpenAPI document: fields, ranges, defaults")


class Catalog(BaseModel):
    controllers: list[ControllerOut] = Field(description="the closed-loop laws, in the order choosers list them")
    job_kinds: list[JobKindOut] = Field(
        description="the batch jobs POST /api/v1/jobs takes, in the order choosers list them"
    )
