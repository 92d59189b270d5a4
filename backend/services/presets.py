"""Which model a request means: a preset's name — built in (:data:`sim_core.model.presets.PRESETS`) or a
calibration stored by ``parkour calibrate`` — resolved to the robot it describes, in one place for
the API (:func:`preset_resolved` for runs and quick calls), the jobs (:func:`with_preset_resolved`:
a job keeps the numbers), the 3D view and the CLI (``cli.options.build_setup``).

Light: a built-in preset needs neither the store nor SQLAlchemy; the store's repository is loaded
only for a name that is not built in, so a command with ``--preset paper`` starts at once.
"""

from __future__ import annotations

from collections.abc import Awaitable, Callable
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Any

from sim_core.model.controls import NO_OFFSETS, LegOffsets
from sim_core.model.errors import ParameterError
from sim_core.model.params import ModelParams, PhysicalParams
from sim_core.model.presets import PRESETS

if TYPE_CHECKING:
    from sqlalchemy.orm import Session

FITTED = ("alpha", "c_zeta", "c_psi")  # what a calibration fits of the nondimensional model


@dataclass(frozen=True)
class ResolvedModel:
    """What a preset's name means.

    Attributes:
        preset: the built-in preset it starts from (a stored calibration's base).
        robot: its robot in SI (a stored calibration's fitted one).
        offsets: the legs' fitted offsets (none for a built-in preset).
        fitted: a stored calibration's fitted ``alpha``, ``c_zeta``, ``c_psi`` (nondimensional);
            empty for a built-in preset.
    """

    preset: str
    robot: PhysicalParams
    offsets: LegOffsets = NO_OFFSETS
    fitted: dict[str, float] = field(default_factory=dict)

    def model(self, **overrides: float | None) -> ModelParams:
        """The robot's nondimensional model with every non-None override applied."""
        return replace(self.robot.to_model(), **{k: v for k, v in overrides.items() if v is not None})


def resolve_model(session: Session | None, preset: str, *, field: str = "preset") -> ResolvedModel:
    """The model preset ``preset`` names: a built-in one, else one stored in ``session``'s database
    (None: built-in presets only). An unknown name is a :class:`ParameterError` on ``field`` naming
    the known presets."""
    if preset in PRESETS:
        return ResolvedModel(preset, PRESETS[preset])
    from backend.repositories import calibrations as stored_presets  # the store, only for a stored preset

    stored = None if session is None else stored_presets.named(session, preset)
    if stored is None:
        known = sorted(PRESETS) + ([] if session is None else [p.name for p in stored_presets.all_presets(session)])
        raise ParameterError(field, f"unknown preset {preset!r}; known presets: {', '.join(known)}")
    robot = PhysicalParams(**stored.physical)
    offsets = LegOffsets(
        psi0_offset_deg=tuple(stored.offsets["psi0_offset_deg"]), zeta0_offset=tuple(stored.offsets["zeta0_offset"])
    )
    fitted_model = robot.to_model()
    return ResolvedModel(stored.base, robot, offsets, {name: getattr(fitted_model, name) for name in FITTED})


def with_preset_resolved(session: Session, body):
    """``body`` (a request with ``model``, a :class:`~backend.schemas.ModelIn`) with a stored preset
    replaced by what it is (:func:`resolve_model`): its base preset and the
    fitted ``alpha``, ``c_zeta``, ``c_psi`` where the request does not override them — numbers a job
    keeps even if the preset is deleted later. A built-in preset passes through; an unknown name is
    a :class:`ParameterError` naming ``model.preset``."""
    model = body.model
    if model.preset in PRESETS:
        return body
    resolved = resolve_model(session, model.preset, field="model.preset")
    fields = {name: value for name, value in resolved.fitted.items() if getattr(model, name) is None}
    return body.model_copy(update={"model": model.model_copy(update={"preset": resolved.preset, **fields})})


# ``await in_session(work, *args)``: ``work(session, *args)`` in a request thread with a session of
# its own (the API's ``Database``).
InSession = Callable[..., Awaitable[Any]]


async def preset_resolved(in_session: InSession, body):
    """:func:`with_preset_resolved` for an ``async`` caller: at once for a built-in preset, else
    through ``in_session`` (``await in_session(work, *args)`` runs ``work(session, *args)`` in a
    request thread: the API's ``Database``)."""
    if body.model.preset in PRESETS:
        return body
    return await in_session(with_preset_resolved, body)
