"""The models the live view's ghost can predict with: the service's robot (the paper's preset) or a
calibration stored by name (docs/calibration.md), its legs' offsets applied to the commanded controls."""

from __future__ import annotations

from collections.abc import Callable

from backend.services import calibrations
from sim_core import LegControl, PhysicalParams
from sim_core.model.controls import NO_OFFSETS, LegOffsets
from sim_core.model.walls import Wall

BASE = "paper"


def model_choices(sessions: Callable | None) -> tuple[str, ...]:
    """``("paper", <stored calibrations, oldest first>)``; the paper alone when there is no store."""
    if sessions is None:
        return (BASE,)
    with sessions() as session:
        return (BASE, *(preset.name for preset in calibrations.list_presets(session)))


def ghost_model(sessions: Callable | None, name: str) -> tuple[PhysicalParams, LegOffsets]:
    """The robot and leg offsets of choice ``name`` (:func:`model_choices`)."""
    if sessions is None or name == BASE:
        return calibrations.preset_params(None, BASE)
    with sessions() as session:
        return calibrations.preset_params(session, name)


def realised(offsets: LegOffsets, leg: LegControl, wall: Wall) -> LegControl:
    """``leg`` as the leg on ``wall`` realises it under ``offsets``; the commanded one if that leaves the domain."""
    if offsets == NO_OFFSETS:
        return leg
    try:
        return offsets.applied(leg, right_leg=wall == Wall.RIGHT)
    except ValueError:
        return leg
