"""The live ghost's models (frontend/viewer/ghost_models.py): the paper's, or a calibration stored by
name, oldest first; its legs' offsets applied to the commanded controls while they stay usable."""

from __future__ import annotations

import dataclasses

import pytest

from backend.store.database import make_engine, migrate, session_factory, sqlite_url
from backend.store.models import ModelPreset
from frontend.viewer.ghost_models import BASE, ghost_model, model_choices, realised
from sim_core import LegControl, get_preset
from sim_core.model.controls import NO_OFFSETS, LegOffsets
from sim_core.model.walls import Wall

PAPER = get_preset("paper")
OFFSETS = LegOffsets(psi0_offset_deg=(0.6, -0.8), zeta0_offset=(0.004, -0.005))
LEG = LegControl.from_degrees(30, 0.9)


@pytest.fixture
def sessions(tmp_path):
    """A migrated store holding two calibrations, "heavy" stored before "stiff"."""
    engine = make_engine(sqlite_url(tmp_path))
    migrate(engine)
    sessions = session_factory(engine)
    for name, robot in (("heavy", dataclasses.replace(PAPER, mass=2.0)), ("stiff", PAPER)):
        with sessions() as session:
            session.add(ModelPreset(name=name, base="paper", physical=dataclasses.asdict(robot),
                                    offsets=OFFSETS.to_dict(), fit={}, runs=[], code_version="test"))  # fmt: skip
            session.commit()
    yield sessions
    engine.dispose()


def test_without_a_store_the_paper_is_the_one_choice():
    assert model_choices(None) == (BASE,) == ("paper",)
    assert ghost_model(None, BASE) == (PAPER, NO_OFFSETS)
    assert ghost_model(None, "anything") == (PAPER, NO_OFFSETS), "there is nothing else to predict with"


def test_stored_calibrations_follow_the_paper_oldest_first(sessions):
    assert model_choices(sessions) == ("paper", "heavy", "stiff")
    robot, offsets = ghost_model(sessions, "heavy")
    assert robot.mass == 2.0 and offsets == OFFSETS
    assert ghost_model(sessions, BASE) == (PAPER, NO_OFFSETS)


def test_each_leg_realises_the_commanded_controls_with_its_offsets():
    assert realised(NO_OFFSETS, LEG, Wall.RIGHT) is LEG
    left, right = realised(OFFSETS, LEG, Wall.LEFT), realised(OFFSETS, LEG, Wall.RIGHT)
    assert (left.psi0_deg, left.zeta0) == (pytest.approx(30.6), pytest.approx(0.904))
    assert (right.psi0_deg, right.zeta0) == (pytest.approx(29.2), pytest.approx(0.895))


def test_a_leg_pushed_out_of_the_domain_keeps_the_commanded_controls():
    near_full_length = LegControl.from_degrees(30, 0.95)
    longer_left = LegOffsets(psi0_offset_deg=(0.0, 0.0), zeta0_offset=(0.06, -0.06))
    assert realised(longer_left, near_full_length, Wall.LEFT) is near_full_length, "zeta0 1.01: not a leg"
    assert realised(longer_left, near_full_length, Wall.RIGHT).zeta0 == pytest.approx(0.89)
