"""Leg controls and cyclic schedules: units, validation that names the field, the kernels' layout."""

import dataclasses
import math

import numpy as np
import pytest

from sim_core import ControlSchedule, LegControl, ParameterError
from sim_core.model.controls import PSI0_COLUMN, ZETA0_COLUMN

DEGREE_ROUND_TRIP_RTOL = 1e-15  # degrees -> radians -> degrees loses at most an ulp or two


def test_from_degrees_stores_radians_and_reads_back_degrees():
    leg = LegControl.from_degrees(30, 0.9)
    assert leg.psi0 == math.radians(30.0) and leg.zeta0 == 0.9
    assert isinstance(leg.psi0, float) and isinstance(leg.zeta0, float), "ints from a UI become floats"
    assert leg.psi0_deg == pytest.approx(30.0, rel=DEGREE_ROUND_TRIP_RTOL)
    assert LegControl.from_degrees(30.0, 0.9) == LegControl(psi0=math.radians(30.0), zeta0=0.9)


def test_stored_energy_is_the_spring_energy_at_touchdown():
    """``alpha (1 - zeta0)^2 / 2`` [m g l0]: more retraction stores more."""
    assert LegControl.from_degrees(30.0, 0.9).stored_energy(80.0) == pytest.approx(0.4, rel=1e-12)
    energies = [LegControl.from_degrees(30.0, zeta0).stored_energy(77.6) for zeta0 in (0.95, 0.9, 0.85)]
    assert energies == sorted(energies)


def test_controls_are_frozen():
    leg = LegControl.from_degrees(30.0, 0.9)
    with pytest.raises(dataclasses.FrozenInstanceError):
        leg.zeta0 = 0.5  # type: ignore[misc]


@pytest.mark.parametrize(
    ("psi0_deg", "zeta0", "field", "range_text"),
    [
        (30.0, 1.0, "zeta0", "(0, 1)"),
        (30.0, 1.2, "zeta0", "(0, 1)"),
        (30.0, 0.0, "zeta0", "(0, 1)"),
        (30.0, math.nan, "zeta0", "finite"),
        (0.0, 0.9, "psi0", "(0, 90)"),
        (90.0, 0.9, "psi0", "(0, 90)"),
        (-10.0, 0.9, "psi0", "(0, 90)"),
        (math.nan, 0.9, "psi0", "finite"),
        ("thirty", 0.9, "psi0", "number"),
    ],
)
def test_from_degrees_errors_name_the_field_and_range(psi0_deg, zeta0, field, range_text):
    with pytest.raises(ParameterError) as error:
        LegControl.from_degrees(psi0_deg, zeta0)
    assert error.value.field == field
    assert str(error.value).startswith(f"{field}: ") and range_text in str(error.value)


@pytest.mark.parametrize("psi0", [0.0, math.pi / 2, -0.1, math.inf, math.nan])
def test_radians_out_of_range_are_reported_in_degrees(psi0):
    """The error speaks degrees, as people state the angle, even for a control built in radians."""
    with pytest.raises(ParameterError) as error:
        LegControl(psi0=psi0, zeta0=0.9)
    assert error.value.field == "psi0" and "(0, 90) degrees" in str(error.value)


def test_schedule_indexing_is_cyclic():
    schedule = ControlSchedule.from_degrees([(30.0, 0.87), (35.0, 0.9), (40.0, 0.93)])
    assert len(schedule) == 3
    for jump in range(9):
        assert schedule[jump] is schedule.legs[jump % 3], f"jump {jump}"
    assert schedule[-1] is schedule.legs[2], "jump -1 is the last leg of the cycle"
    symmetric = ControlSchedule.from_degrees([(30.0, 0.9)])
    assert symmetric[0] is symmetric[1] is symmetric[1000]


def test_of_and_from_degrees_build_the_same_schedule():
    left, right = LegControl.from_degrees(30.0, 0.87), LegControl.from_degrees(30.0, 0.9)
    assert ControlSchedule.of(left, right) == ControlSchedule.from_degrees(iter([(30.0, 0.87), (30.0, 0.9)]))
    assert ControlSchedule.of(left, right).legs == (left, right)


def test_empty_schedule_and_foreign_items_name_controls():
    with pytest.raises(ParameterError) as error:
        ControlSchedule(())
    assert error.value.field == "controls" and "at least one" in str(error.value)
    with pytest.raises(ParameterError) as error:
        ControlSchedule.from_degrees([])
    assert error.value.field == "controls"
    with pytest.raises(ParameterError) as error:
        ControlSchedule(((30.0, 0.9),))  # type: ignore[arg-type]
    assert error.value.field == "controls" and "tuple" in str(error.value)


def test_schedule_errors_name_the_bad_leg_field():
    with pytest.raises(ParameterError) as error:
        ControlSchedule.from_degrees([(30.0, 0.9), (30.0, 1.5)])
    assert error.value.field == "zeta0"


def test_as_array_layout_is_the_kernels():
    schedule = ControlSchedule.from_degrees([(30.0, 0.87), (35.0, 0.9)])
    array = schedule.as_array()
    assert array.shape == (2, 2) and array.dtype == np.float64 and array.flags.c_contiguous
    assert (PSI0_COLUMN, ZETA0_COLUMN) == (0, 1)
    np.testing.assert_array_equal(array[:, PSI0_COLUMN], [math.radians(30.0), math.radians(35.0)])
    np.testing.assert_array_equal(array[:, ZETA0_COLUMN], [0.87, 0.9])
    array[0, 0] = 0.0
    assert schedule[0].psi0 == math.radians(30.0), "the array is a copy: the schedule stays as it was"


def test_describe_reads_as_people_state_controls():
    assert ControlSchedule.from_degrees([(30.0, 0.87), (35.0, 0.9)]).describe() == "30°:0.87, 35°:0.9"
    assert ControlSchedule.from_degrees([(27.5, 0.905)]).describe() == "27.5°:0.905"


def test_describe_without_degree_signs_builds_the_same_schedule():
    """The docstring's promise: what describe() prints is what the CLI reads back."""
    schedule = ControlSchedule.from_degrees([(30.0, 0.87), (35.0, 0.9), (27.5, 0.905)])
    pairs = [item.replace("°", "").split(":") for item in schedule.describe().split(", ")]
    again = ControlSchedule.from_degrees([(float(psi), float(zeta)) for psi, zeta in pairs])
    np.testing.assert_allclose(again.as_array(), schedule.as_array(), rtol=DEGREE_ROUND_TRIP_RTOL, atol=0)
