"""What every request body shares (backend/schemas/common.py): the strict base, the leg, model and
state inputs with their ranges, record references, tags and the page of a list."""

import datetime
import math

import pytest
from pydantic import BaseModel, TypeAdapter, ValidationError

from backend.jobs.specs import ModelSpec
from backend.schemas.common import (
    MAX_FRICTION,
    MAX_ID,
    IsoDateTime,
    Label,
    LegIn,
    ModelIn,
    Notes,
    Page,
    Psi0Deg,
    RecordRef,
    StateIn,
    Tags,
    Zeta0,
    finite_or_none,
)
from sim_core.model.errors import ParameterError
from tests.backend.schemas.refusals import LEG, START, accepted, refused

NON_FINITE = [math.nan, math.inf, -math.inf]


@pytest.mark.parametrize(
    ("kind", "inside", "outside"),
    [
        (Psi0Deg, [1e-9, 45.0, 89.999], [0.0, -1.0, 90.0, 120.0]),
        (Zeta0, [1e-9, 0.9, 0.999999], [0.0, -0.1, 1.0, 1.2]),
        (RecordRef, [1, MAX_ID], [0, -1, MAX_ID + 1]),
    ],
    ids=["psi0_deg (0, 90)", "zeta0 (0, 1)", "record id [1, 2^31-1]"],
)
def test_scalar_ranges_accept_just_inside_and_refuse_just_outside(kind, inside, outside):
    adapter = TypeAdapter(kind)
    for value in inside:
        assert adapter.validate_python(value) == value
    for value in outside:
        with pytest.raises(ValidationError):
            adapter.validate_python(value)


@pytest.mark.parametrize(
    ("field", "inside", "outside"),
    [
        ("psi0_deg", 89.99, 90.0),
        ("psi0_deg", 0.01, 0.0),
        ("zeta0", 0.99, 1.0),
        ("zeta0", 0.01, 0.0),
    ],
)
def test_a_leg_outside_its_range_is_refused_naming_the_field(field, inside, outside):
    assert getattr(accepted(LegIn, LEG | {field: inside}), field) == inside
    assert refused(LegIn, LEG | {field: outside}) == [(field,)]


def test_a_leg_angle_that_is_0_once_in_radians_is_refused_on_psi0_deg():
    """5e-324 degrees is inside (0, 90) but 0 radians: the kernels would get a leg along the wall."""
    assert refused(LegIn, LEG | {"psi0_deg": 5e-324}) == [("psi0_deg",)]
    assert accepted(LegIn, LEG | {"psi0_deg": 1e-9}).psi0_deg == 1e-9  # the schema's minimum, said in the document


@pytest.mark.parametrize(
    ("field", "inside", "outside"),
    [
        ("xdot", -1e-9, 0.0),  # the section is crossed moving left: xdot < 0
        ("xdot", -100.0, -100.01),
        ("ydot", 100.0, 100.01),
        ("ydot", -100.0, -100.01),
    ],
)
def test_a_state_outside_its_range_is_refused_naming_the_field(field, inside, outside):
    assert getattr(accepted(StateIn, START | {field: inside}), field) == inside
    assert refused(StateIn, START | {field: outside}) == [(field,)]


@pytest.mark.parametrize(
    ("field", "inside", "outside"),
    [
        ("alpha", 1e4, 1e4 + 1),
        ("alpha", 1e-9, 0.0),
        ("d_hat", 100.0, 100.01),
        ("d_hat", 1e-9, 0.0),
        ("c_zeta", 0.0, -1e-9),
        ("c_zeta", 1e3, 1e3 + 1),
        ("c_psi", 0.0, -1e-9),
        ("c_psi", 1e3, 1e3 + 1),
        ("mu", 1e-9, 0.0),
        ("mu", MAX_FRICTION, MAX_FRICTION + 0.01),
    ],
)
def test_model_overrides_outside_their_range_are_refused_naming_the_field(field, inside, outside):
    assert getattr(accepted(ModelIn, {field: inside}), field) == inside
    assert refused(ModelIn, {field: outside}) == [(field,)]


def test_a_model_is_the_paper_preset_with_no_overrides_unless_told():
    model = ModelIn()
    assert model.preset == "paper"
    assert (model.alpha, model.d_hat, model.c_zeta, model.c_psi, model.mu) == (None,) * 5


@pytest.mark.parametrize("preset", ["paper", "table.v1", "lab-2026_12", "x" * 64])
def test_a_preset_name_may_be_a_stored_calibrations(preset):
    assert accepted(ModelIn, {"preset": preset}).preset == preset


@pytest.mark.parametrize("preset", ["", "-x", ".hidden", "a b", "x/y", "x" * 65])
def test_a_preset_name_outside_the_pattern_is_refused(preset):
    assert refused(ModelIn, {"preset": preset}) == [("preset",)]


@pytest.mark.parametrize("value", NON_FINITE)
@pytest.mark.parametrize(
    ("schema", "body", "loc"),
    [
        (LegIn, LEG | {"zeta0": "@"}, ("zeta0",)),
        (StateIn, START | {"ydot": "@"}, ("ydot",)),
        (ModelIn, {"mu": "@"}, ("mu",)),  # infinite friction is the kernels' "no slip", never a request's
    ],
)
def test_non_finite_numbers_are_refused_naming_the_field(schema, body, loc, value):
    body = {key: value if item == "@" else item for key, item in body.items()}
    assert refused(schema, body) == [loc]


def test_a_number_json_makes_infinite_is_refused():
    """``1e309`` is a finite literal that JSON parsing turns into infinity."""
    with pytest.raises(ValidationError) as refusal:
        StateIn.model_validate_json('{"xdot": -1e309, "ydot": 0}')
    assert [error["loc"] for error in refusal.value.errors()] == [("xdot",)]


@pytest.mark.parametrize("schema", [LegIn, StateIn, ModelIn])
def test_unknown_fields_are_refused_by_name(schema):
    body = {LegIn: LEG, StateIn: START, ModelIn: {}}[schema]
    assert refused(schema, body | {"colour": "red"}) == [("colour",)]


@pytest.mark.parametrize("label", ["a", "zeta0:0.9", "run/2026-12.v1", "x" * 64])
def test_a_label_is_a_short_word_with_dots_colons_slashes_and_dashes(label):
    assert TypeAdapter(Label).validate_python(label) == label


@pytest.mark.parametrize("label", ["", "x" * 65, "two words", "semi;colon", "new\nline", "a\ud800"])
def test_a_label_outside_the_pattern_is_refused(label):
    with pytest.raises(ValidationError):
        TypeAdapter(Label).validate_python(label)


def test_tags_are_at_most_32_labels_and_notes_at_most_100_000_characters():
    assert len(TypeAdapter(Tags).validate_python([f"t{i}" for i in range(32)])) == 32
    with pytest.raises(ValidationError):
        TypeAdapter(Tags).validate_python([f"t{i}" for i in range(33)])
    assert len(TypeAdapter(Notes).validate_python("n" * 100_000)) == 100_000
    with pytest.raises(ValidationError):
        TypeAdapter(Notes).validate_python("n" * 100_001)


class _Item(BaseModel):
    id: int


def test_a_page_ends_with_a_null_cursor_unless_one_is_given():
    last = Page[_Item](items=[_Item(id=2), _Item(id=1)])
    assert last.next_cursor is None
    assert Page[_Item].model_validate_json(last.model_dump_json()) == last
    middle = Page[_Item](items=[{"id": 9}], next_cursor=9)
    assert middle.items == [_Item(id=9)] and middle.next_cursor == 9
    assert Page[_Item].model_validate_json(middle.model_dump_json()) == middle


@pytest.mark.parametrize(
    ("value", "sent"), [(0.5, 0.5), (-3.0, -3.0), (math.nan, None), (math.inf, None), (-math.inf, None)]
)
def test_finite_or_none_sends_null_for_what_json_cannot_hold(value, sent):
    assert finite_or_none(value) == sent


@pytest.mark.parametrize(
    ("text", "moment"),
    [
        ("2026-12-03", datetime.datetime(2026, 12, 3)),
        ("2026-12-03T14:00:00Z", datetime.datetime(2026, 12, 3, 14, 0, tzinfo=datetime.UTC)),
        ("2026-12-03T14:00:00+02:00", datetime.datetime(2026, 12, 3, 12, 0, tzinfo=datetime.UTC)),
    ],
)
def test_a_moment_is_an_iso_8601_date_or_time(text, moment):
    assert TypeAdapter(IsoDateTime).validate_python(text) == moment


@pytest.mark.parametrize("text", ["0.5", "1733234400", "yesterday", "03/12/2026", ""])
def test_anything_but_iso_8601_is_refused_with_an_example(text):
    """Pydantic alone reads a number as seconds since 1970: "0.5" would be a date."""
    with pytest.raises(ValidationError, match=r"must be an ISO 8601 date or time, e\.g\. 2026-12-03"):
        TypeAdapter(IsoDateTime).validate_python(text)


def test_a_requests_model_starts_from_its_preset(paper):
    assert ModelIn().params() == paper
    changed = ModelIn(alpha=40.0, mu=1.5).params()
    assert (changed.alpha, changed.mu, changed.d_hat, changed.c_zeta) == (40.0, 1.5, paper.d_hat, paper.c_zeta)


def test_a_stored_jobs_model_is_its_requests():
    request = ModelIn(alpha=40.0, c_psi=0.2)
    assert ModelSpec(**request.model_dump()).params() == request.params()
    with pytest.raises(ParameterError) as unknown:
        ModelSpec(preset="gone").params()
    assert unknown.value.field == "model.preset" and "paper" in unknown.value.message


def test_every_leg_angle_the_schema_allows_is_accepted_and_inside_in_radians():
    """The OpenAPI document's bounds are the ones held to (schemathesis found 5e-324 allowed there, refused here)."""
    schema = LegIn.model_json_schema()["properties"]["psi0_deg"]
    low, high = schema["minimum"], schema["exclusiveMaximum"]
    for value in (low, math.nextafter(low, 90.0), 45.0, math.nextafter(high, 0.0)):
        assert accepted(LegIn, LEG | {"psi0_deg": value}).psi0_deg == value
        assert 0.0 < math.radians(value) < math.pi / 2, "the kernels get an angle off the wall and off the normal"
    for value in (math.nextafter(low, 0.0), 5e-324, 0.0, high):
        assert refused(LegIn, LEG | {"psi0_deg": value}) == [("psi0_deg",)]
