"""The service's registries as the API shows them (:mod:`backend.schemas.catalog`)."""

from __future__ import annotations

from backend import schemas
from backend.jobs import KINDS
from sim_core.control.registry import LAWS


def catalog() -> schemas.Catalog:
    """The controllers registered in sim_core and the job kinds registered in backend.jobs, in their order."""
    controllers = [schemas.ControllerOut(name=law.name, summary=law.summary, sets_leg_angle=law.sets_leg_angle)
                   for law in LAWS.values()]  # fmt: skip
    job_kinds = [schemas.JobKindOut(name=kind.name, title=kind.title, request=kind.request.__name__) for kind in KINDS]
    return schemas.Catalog(controllers=controllers, job_kinds=job_kinds)
