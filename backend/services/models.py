"""Which model a request means: a preset's name — built in (:data:`sim_core.presets.PRESETS`) or a
calibration stored by ``parkour calibrate`` — resolved to the robot it describes, in one place for
the API (``deps.preset_resolved``, :func:`backend.services.calibrations.with_preset_resolved`), the
jobs and the CLI (``cli.options.build_setup``).

Light: a built-in preset needs neither the store nor SQLAlchemy; the store's repository is loaded
only for a name that is not built in, so a command with ``--preset paper`` starts at once.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING

from sim_core.controls import NO_OFFSETS, LegOffsets
from sim_core.errors import ParameterError
from sim_core.params import ModelParams, PhysicalParams
from sim_core.presets import PRESETS

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
