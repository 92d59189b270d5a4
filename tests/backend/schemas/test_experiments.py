"""Experiments' bodies (backend/schemas/experiments.py): a name, a description, notes and tags,
created strictly, edited field by field, and read back whatever the limits were when stored."""

import datetime

import pytest

from backend.schemas.experiments import ExperimentCreate, ExperimentOut, ExperimentPage, ExperimentUpdate
from tests.backend.schemas.refusals import accepted, refused

NOW = datetime.datetime(2026, 12, 1, 12, 0, tzinfo=datetime.UTC)


@pytest.mark.parametrize(
    ("field", "inside", "outside"),
    [
        ("name", "n" * 200, "n" * 201),
        ("description", "d" * 10_000, "d" * 10_001),
        ("notes", "n" * 100_000, "n" * 100_001),
        ("tags", [f"t{i}" for i in range(32)], [f"t{i}" for i in range(33)]),
    ],
)
def test_each_field_has_a_limit_named_when_passed(field, inside, outside):
    body = {"name": "energy"}
    assert getattr(accepted(ExperimentCreate, body | {field: inside}), field) == inside
    assert refused(ExperimentCreate, body | {field: outside}) == [(field,)]
    assert getattr(accepted(ExperimentUpdate, {field: inside}), field) == inside
    assert refused(ExperimentUpdate, {field: outside}) == [(field,)]


def test_an_experiment_needs_a_name_and_defaults_the_rest_to_empty():
    created = accepted(ExperimentCreate, {"name": "energy"})
    assert (created.description, created.notes, created.tags) == ("", "", [])
    assert refused(ExperimentCreate, {}) == [("name",)]
    assert refused(ExperimentCreate, {"name": ""}) == [("name",)]


def test_a_tag_is_a_label():
    assert refused(ExperimentCreate, {"name": "e", "tags": ["ok", "not ok"]}) == [("tags", 1)]


@pytest.mark.parametrize("schema", [ExperimentCreate, ExperimentUpdate])
def test_unknown_fields_are_refused(schema):
    assert refused(schema, {"name": "e", "runs": 3}) == [("runs",)]


def test_an_update_changes_only_the_fields_it_names():
    update = accepted(ExperimentUpdate, {"notes": "second try"})
    assert update.model_dump(exclude_none=True) == {"notes": "second try"}
    assert accepted(ExperimentUpdate, {}).model_dump(exclude_none=True) == {}
    assert accepted(ExperimentUpdate, {"name": None}).name is None, "null: left as it is"


def test_a_stored_experiment_reads_back_even_beyond_todays_limits():
    stored = {
        "id": 1,
        "name": "n" * 500,  # stored under an older, longer limit
        "description": "",
        "notes": "",
        "tags": ["two words"],
        "created_at": NOW,
        "updated_at": NOW,
        "runs": 3,
    }
    out = ExperimentOut.model_validate(stored)
    assert (out.name, out.tags, out.runs) == ("n" * 500, ["two words"], 3)
    page = ExperimentPage(items=[out], next_cursor=None)
    assert ExperimentPage.model_validate_json(page.model_dump_json()) == page
