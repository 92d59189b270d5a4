"""A request's model and controls as sim_core's: what every simulation, quick call and job starts from.

A request's :class:`~backend.schemas.ModelIn`, or a stored job's ModelSpec, is its preset
(:func:`~backend.services.presets.resolve_model`) with the request's overrides; its legs are a
:class:`~sim_core.model.controls.ControlSchedule`.
"""

from __future__ import annotations

from dataclasses import asdict

from backend.jobs.base import schedule_of
from backend.schemas import ModelIn
from backend.services.presets import resolve_model
from sim_core.model.params import ModelParams

__all__ = ["model_params", "schedule_of"]  # the legs' conversion lives with the jobs, which share it


def model_params(body) -> ModelParams:
    """A request's :class:`~backend.schemas.ModelIn` or a stored job's ModelSpec as the model: its
    preset (:func:`~backend.services.presets.resolve_model`; a stored one is resolved to its base
    before it gets here) with the request's overrides."""
    fields = body.model_dump() if isinstance(body, ModelIn) else asdict(body)
    overrides = {name: value for name, value in fields.items() if name != "preset"}
    return resolve_model(None, fields["preset"], field="model.preset").model(**overrides)
