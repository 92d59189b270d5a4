"""The quick simulations' bodies (backend/schemas/sim.py): the map, a sampled path and a gait,
each bounded so a person waits seconds, and the answers the compute worker sends back."""

import pytest

from backend.schemas.sim import FixedPointIn, FixedPointOut, MapIn, MapOut, TrajectoryIn, TrajectoryOut
from tests.backend.schemas.refusals import LEG, START, accepted, refused

MAP = {"controls": [LEG], "start": START}


@pytest.mark.parametrize(
    ("schema", "field", "inside", "outside"),
    [
        (MapIn, "jumps", 1000, 1001),
        (MapIn, "jumps", 1, 0),
        (TrajectoryIn, "jumps", 50, 51),
        (TrajectoryIn, "jumps", 1, 0),
        (TrajectoryIn, "rate", 500.0, 500.01),
        (TrajectoryIn, "rate", 1e-9, 0.0),
    ],
)
def test_a_quick_call_is_bounded_naming_the_limit_passed(schema, field, inside, outside):
    assert getattr(accepted(schema, MAP | {field: inside}), field) == inside
    assert refused(schema, MAP | {field: outside}) == [(field,)]


@pytest.mark.parametrize("schema", [MapIn, TrajectoryIn, FixedPointIn])
def test_a_schedule_has_1_to_16_legs(schema):
    body = MAP if schema is not FixedPointIn else {"controls": [LEG]}
    assert len(accepted(schema, body | {"controls": [LEG] * 16}).controls) == 16
    assert refused(schema, body | {"controls": [LEG] * 17}) == [("controls",)]
    assert refused(schema, body | {"controls": []}) == [("controls",)]


def test_nested_errors_name_the_leg_and_the_model_field():
    bad_leg = MAP | {"controls": [LEG, LEG | {"zeta0": 1.0}]}
    assert refused(MapIn, bad_leg) == [("controls", 1, "zeta0")]
    assert refused(MapIn, MAP | {"model": {"alpha": 0.0}}) == [("model", "alpha")]
    assert refused(MapIn, MAP | {"start": START | {"xdot": 0.5}}) == [("start", "xdot")]


def test_defaults_are_the_paper_model_and_a_short_call():
    orbit = accepted(MapIn, MAP)
    assert (orbit.model.preset, orbit.jumps) == ("paper", 1)
    path = accepted(TrajectoryIn, MAP)
    assert (path.jumps, path.rate) == (4, 60.0)
    gait = accepted(FixedPointIn, {"controls": [LEG]})
    assert (gait.period, gait.guess) == (None, None), "period and guess searched for unless given"


def test_a_gait_search_is_bounded_in_period_and_needs_no_start():
    body = {"controls": [LEG]}
    assert accepted(FixedPointIn, body | {"period": 16, "guess": START}).period == 16
    assert refused(FixedPointIn, body | {"period": 17}) == [("period",)]
    assert refused(FixedPointIn, body | {"period": 0}) == [("period",)]
    assert refused(FixedPointIn, body | {"start": START}) == [("start",)], "a gait has a guess, not a start"


@pytest.mark.parametrize("schema", [MapIn, TrajectoryIn])
def test_a_map_or_a_path_needs_a_start_and_refuses_unknown_fields(schema):
    assert refused(schema, {"controls": [LEG]}) == [("start",)]
    assert refused(schema, MAP | {"steps": 3}) == [("steps",)]


def test_answers_carry_nulls_where_the_numbers_were_not_finite():
    failed = MapOut(states=[[-0.93, -0.17], [None, None]], rises=[None], failure={"code": "slip", "jump": 0})
    assert MapOut.model_validate_json(failed.model_dump_json()) == failed
    assert failed.failure.code == "slip" and failed.failure.jump == 0
    gait = FixedPointOut(
        state=[-0.93, -0.2], period=1, eigenvalues=[[0.5, 0.6], [0.5, -0.6]], max_abs_eigenvalue=0.781,
        stable=True, climb_per_period=None, residual=1e-12, motion=None, orbit=[[-0.93, -0.2]],
    )  # fmt: skip
    assert FixedPointOut.model_validate(gait.model_dump()) == gait


def test_a_path_answer_keeps_its_columns_and_si_scales():
    path = {
        "units": "nondimensional",
        "columns": {"time": [0.0, 0.1], "phase": [0, 1], "x": [0.0, None]},
        "touchdown_times": [0.1],
        "failure": None,
        "walls_x": [-1.21, 1.21],
        "si": {"preset": "paper", "l0_m": 0.223, "time_s": 0.477, "speed_m_per_s": 0.467},
    }
    answer = TrajectoryOut.model_validate(path)
    assert answer.columns["phase"] == [0, 1] and answer.si.preset == "paper"
    assert answer.model_dump() == path
