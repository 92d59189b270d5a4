"""The JSON channels of a run's MCAP recording (backend/services/mcap_schemas.py): topics in the
order they are registered, each with a draft 2020-12 JSON Schema the MCAP tools and Foxglove read."""

import json

import pytest

from backend.services.mcap_schemas import CHANNELS, SECTION_STATE, TOUCHDOWN, TRACKER_POSE

JSON_TYPES = {"object", "array", "string", "integer", "number", "null", "boolean"}
DRAFT = "https://json-schema.org/draft/2020-12/schema"


def _types(schema: dict, where: str = "$"):
    """(place, type) of every ``type`` keyword in ``schema``, recursively."""
    types = schema.get("type")
    for name in [types] if isinstance(types, str) else types or []:
        yield where, name
    for key, item in schema.get("properties", {}).items():
        yield from _types(item, f"{where}.{key}")
    if isinstance(schema.get("items"), dict):
        yield from _types(schema["items"], f"{where}[]")


def test_channels_are_registered_in_this_order():
    assert list(CHANNELS) == [
        "/tracker/pose",
        "/touchdowns",
        "/commands",
        "/telemetry",
        "/model/prediction",
        "/robot/link",
    ]


@pytest.mark.parametrize("topic", CHANNELS)
def test_each_channel_is_a_titled_object_schema_requiring_only_what_it_describes(topic):
    schema = CHANNELS[topic]
    assert schema["$schema"] == DRAFT and schema["type"] == "object"
    assert schema["title"] and schema["description"]
    assert set(schema["required"]) <= set(schema["properties"]), "a required field the schema does not describe"
    assert json.loads(json.dumps(schema)) == schema, "stored in the file as JSON"


@pytest.mark.parametrize("topic", CHANNELS)
def test_every_type_named_is_a_json_type(topic):
    places = list(_types(CHANNELS[topic]))
    assert places, topic
    assert [(where, name) for where, name in places if name not in JSON_TYPES] == []


def test_schema_names_are_unique_and_ours():
    """Foxglove's own schemas (the body's pose) are protobuf channels: backend/services/mcap_visuals.py."""
    titles = [schema["title"] for schema in CHANNELS.values()]
    assert len(set(titles)) == len(titles)
    assert [title for title in titles if not title.startswith("parkourlab.")] == []


def test_values_that_may_be_missing_are_nullable_and_the_rest_are_not():
    assert "null" in TRACKER_POSE["properties"]["pitch"]["type"], "an untracked pitch"
    assert "null" in TOUCHDOWN["properties"]["rise"]["type"], "the first touchdown has no rise"
    assert "null" in TOUCHDOWN["properties"]["control"]["type"]
    assert TRACKER_POSE["properties"]["x"]["type"] == "number"
    assert SECTION_STATE["minItems"] == SECTION_STATE["maxItems"] == 2 and "null" in SECTION_STATE["items"]["type"]


def test_a_touchdown_is_on_the_left_or_the_right_wall():
    assert TOUCHDOWN["properties"]["wall"]["enum"] == [-1, 1]
    assert CHANNELS["/commands"]["properties"]["leg"]["enum"] == ["left", "right"]
