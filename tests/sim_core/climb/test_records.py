"""The climb's records (sim_core.climb.records): samples cut by rows, a jump's stance and flight, the
floor's end; built by hand, no simulation (the sequencer that fills them: test_climb.py)."""

import dataclasses
import math

import numpy as np
import pytest
from numpy.testing import assert_array_equal

from sim_core import LegControl, get_preset
from sim_core.climb.records import (
    FLOOR,
    SAMPLE_RATE,
    ClimbEnd,
    ClimbSetup,
    Jump,
    JumpStart,
    NextLeg,
    Samples,
)
from sim_core.model.failures import Failure
from sim_core.model.trajectory import FLIGHT, STANCE
from sim_core.model.walls import Wall

LEG = LegControl.from_degrees(30, 0.9)


def _samples(phases) -> Samples:
    """Samples whose every column is its row number (plus a column's offset), so rows can be told apart."""
    rows = np.arange(len(phases), dtype=float)
    return Samples(
        time=rows, x=rows + 10, y=rows + 20, foot_x=rows + 30, foot_y=rows + 40, zeta=rows + 50, phase=np.array(phases)
    )


def _jump(samples: Samples, liftoff: int, end=None) -> Jump:
    start = JumpStart(jump=3, wall=Wall.RIGHT, time=0.0, body_height=0.2, state=(-0.9, -0.1), leg=LEG)
    return Jump(
        start=start,
        next=NextLeg(LEG),
        samples=samples,
        liftoff=liftoff,
        end=end,
        rise=math.nan if end else 0.01,
        duration=math.nan if end else 0.3,
        arrival=None if end else (-0.9, -0.1),
    )


def test_take_cuts_every_column_alike():
    samples = _samples([STANCE, STANCE, FLIGHT, FLIGHT, FLIGHT])
    for rows, expected in ((slice(1, 3), [1, 2]), (samples.phase == FLIGHT, [2, 3, 4]), (np.array([4, 0]), [4, 0])):
        part = samples.take(rows)
        assert len(part) == len(expected)
        for offset, name in enumerate(("time", "x", "y", "foot_x", "foot_y", "zeta")):
            assert_array_equal(getattr(part, name), np.array(expected) + 10 * offset, err_msg=name)
        assert_array_equal(part.phase, samples.phase[expected])


def test_take_covers_every_field():
    assert tuple(field.name for field in dataclasses.fields(Samples)) == Samples.COLUMNS


def test_a_jump_splits_at_liftoff():
    done = _jump(_samples([STANCE, STANCE, STANCE, FLIGHT, FLIGHT]), liftoff=3)
    assert done.wall is Wall.RIGHT, "the stance wall is the touchdown's"
    assert_array_equal(done.stance.time, [0, 1, 2])
    assert_array_equal(done.flight.time, [3, 4])
    assert np.all(done.stance.phase == STANCE) and np.all(done.flight.phase == FLIGHT)
    assert done.liftoff_time == 3.0


def test_a_jump_ended_in_stance_has_no_flight_and_lifts_off_at_its_last_sample():
    done = _jump(_samples([STANCE, STANCE, STANCE]), liftoff=3, end=Failure.SLIP)
    assert len(done.flight) == 0 and len(done.stance) == 3
    assert done.liftoff_time == 2.0


def test_the_floor_is_an_end_with_a_code_and_a_message():
    end = ClimbEnd.FLOOR
    assert (end.code, end.message) == ("floor", "the body reached the chute's floor")
    assert (Failure.FLOOR.code, Failure.FLOOR.message) == (end.code, end.message), "a closed loop's run ends alike"


def test_setup_defaults_and_records_are_frozen():
    setup = ClimbSetup(get_preset("paper"))
    assert (setup.sample_rate, setup.floor) == (SAMPLE_RATE, FLOOR) == (200.0, 0.0)
    assert NextLeg(LEG).pitch == 0.0
    with pytest.raises(dataclasses.FrozenInstanceError):
        setup.floor = 1.0  # type: ignore[misc]
