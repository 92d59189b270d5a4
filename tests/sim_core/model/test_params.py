"""Parameters and presets: conversions and clear errors (controls: test_controls.py)."""

import math
from dataclasses import astuple, fields, replace

import pytest

from sim_core import ModelParams, ParameterError, PhysicalParams, get_preset
from sim_core.model.params import ModelRecord


def test_paper_preset_matches_model_md():
    model = get_preset("paper").to_model()
    assert model.alpha == pytest.approx(77.6, abs=0.05)
    assert model.d_hat == pytest.approx(2.42)
    assert model.c_zeta == pytest.approx(0.310, abs=5e-4)
    assert model.c_psi == pytest.approx(0.310, abs=5e-4)
    assert model.mu == 2.0


def test_the_kernels_record_is_the_parameters_field_for_field():
    """ModelRecord names ModelParams' fields in their order, so a parameter added to one and not the
    other fails here; its values are the parameters', as floats (one compiled specialisation)."""
    assert ModelRecord._fields == tuple(field.name for field in fields(ModelParams))
    model = get_preset("paper").to_model()
    assert model.record() == astuple(model) and model.record().mu == model.mu
    whole = ModelParams(alpha=80, d_hat=3).record()
    assert whole == (80.0, 3.0, 0.0, 0.0, math.inf) and all(type(value) is float for value in whole)


def test_physical_model_round_trip():
    robot = get_preset("paper")
    back = PhysicalParams.from_model(
        robot.to_model(), mass=robot.mass, leg_length=robot.leg_length, gravity=robot.gravity
    )
    for field in ("stiffness", "wall_distance", "c_zeta", "c_psi", "mu"):
        assert getattr(back, field) == pytest.approx(getattr(robot, field), rel=1e-14)


def test_scales():
    robot = get_preset("paper")
    scales = robot.scales
    assert scales.time == pytest.approx(math.sqrt(robot.leg_length / robot.gravity))
    assert scales.velocity * scales.time == pytest.approx(scales.length)


@pytest.mark.parametrize(
    ("change", "field"),
    [
        ({"alpha": -1.0}, "alpha"),
        ({"alpha": math.nan}, "alpha"),
        ({"d_hat": 0.0}, "d_hat"),
        ({"c_zeta": -0.1}, "c_zeta"),
        ({"mu": 0.0}, "mu"),
        ({"mu": math.nan}, "mu"),
    ],
)
def test_model_params_validation_names_the_field(change, field):
    with pytest.raises(ParameterError) as error:
        replace(get_preset("paper").to_model(), **change)
    assert error.value.field == field
    assert field in str(error.value) and "must be" in str(error.value)


def test_infinite_friction_is_allowed():
    assert ModelParams(alpha=10.0, d_hat=2.0, mu=math.inf).mu == math.inf


def test_unknown_preset_lists_known_ones():
    with pytest.raises(ParameterError, match="known presets: paper"):
        get_preset("moon")
