"""World files (sim_core/world/files.py, docs/worlds.md): every mistake named by where it is and the
rule, round trips in l0 and in metres, and a parser that refuses anything else with a ParameterError."""

import json
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose, assert_array_equal

from sim_core.model.errors import ParameterError
from sim_core.world.files import load_world, read_document, save_world, world_from_document, world_to_document
from sim_core.world.world import World, parallel

L0_M = 0.54 / 2.42
RTOL_METRES = 1e-14  # metres and back: two roundings


def _document(**changes) -> dict:
    document = {
        "name": "bend",
        "units": "l0",
        "left": {"points": [[-1.2, 0.0], [-1.3, 0.5], [-1.1, 1.0]], "mu": [2.0, None]},
        "right": {"points": [[1.2, 0.0], [1.2, 2.0]], "mu": ["inf"]},
    }
    document.update(changes)
    return document


def _error(document, l0_m=None) -> ParameterError:
    with pytest.raises(ParameterError) as raised:
        world_from_document(document, l0_m)
    return raised.value


def _same(a: World, b: World) -> None:
    for name in ("left", "right"):
        assert_array_equal(a.side(name).points, b.side(name).points, err_msg=name)
        assert_array_equal(a.side(name).mu, b.side(name).mu, err_msg=name)  # NaN equals NaN here
    assert a.name == b.name


def test_a_document_becomes_its_world():
    world = world_from_document(_document())
    assert world.name == "bend" and world.left.segments == 2 and world.right.segments == 1
    assert_array_equal(world.left.points, [[-1.2, 0.0], [-1.3, 0.5], [-1.1, 1.0]])
    assert world.left.mu[0] == 2.0 and math.isnan(world.left.mu[1]) and world.right.mu[0] == math.inf


def test_without_mu_every_segment_has_the_models():
    document = _document()
    del document["left"]["mu"]
    assert np.isnan(world_from_document(document).left.mu).all()


def test_metres_are_converted_with_l0():
    document = _document(units="m")
    world = world_from_document(document, L0_M)
    assert_allclose(world.left.points, np.array(document["left"]["points"]) / L0_M, rtol=RTOL_METRES)


@pytest.mark.parametrize(
    ("changes", "field", "message"),
    [
        ({"units": "ft"}, "units", 'must be "l0" or "m", got "ft"'),
        ({"units": None}, "units", 'must be "l0" or "m", got null'),
        (
            {"colour": "red"},
            "colour",
            "is not a key of a world file; its keys are name, description, units, left, right",
        ),
        (
            {"left": {"points": [[-1, 0], [-1, 1]], "grip": 2}},
            "left.grip",
            "is not a key of a side; its keys are points, mu",
        ),
        ({"name": 3}, "name", "must be a string, got 3"),
        (
            {"right": [[1, 0], [1, 1]]},
            "right",
            'must be an object {"points": [[x, y], ...], "mu": [...]}, got [[1, 0], [1, 1]]',
        ),
        ({"right": {"mu": [1]}}, "right.points", "must be a list of [x, y] pairs bottom to top, got null"),
        (
            {"left": {"points": [[-1, 0]]}},
            "left.points",
            "must have 2 to 257 points (1 to MAX_SEGMENTS = 256 segments), got 1",
        ),
        (
            {"left": {"points": [[-1, 0], [-1, "a"]]}},
            "left.points[1]",
            'must be a pair [x, y] of numbers, got [-1, "a"]',
        ),
        (
            {"left": {"points": [[-1, 0], [-1, 1, 2]]}},
            "left.points[1]",
            "must be a pair [x, y] of numbers, got [-1, 1, 2]",
        ),
        (
            {"left": {"points": [[-1, 0], [True, 1]]}},
            "left.points[1]",
            "must be a pair [x, y] of numbers, got [true, 1]",
        ),
        ({"left": {"points": [[-1, 0], [math.nan, 1]]}}, "left.points[1]", "x must be a finite number, got nan"),
        ({"left": {"points": [[-1, 0], [-1, 10**400]]}}, "left.points[1]", "y must be a finite number, got inf"),
        (
            {"left": {"points": [[-1, 0], [-1, 0.9], [-1, 0.8]]}},
            "left.points[2]",
            "y must increase strictly bottom to top: 0.8 after 0.9",
        ),
        ({"right": {"points": [[1, 0], [1, 1]], "mu": []}}, "right.mu", "must have one entry per segment (1), got 0"),
        (
            {"right": {"points": [[1, 0], [1, 1]], "mu": 2}},
            "right.mu",
            "must be a list with one entry per segment, got 2",
        ),
        (
            {"right": {"points": [[1, 0], [1, 1], [1, 2], [1, 3]], "mu": [0, 1, -1]}},
            "right.mu[2]",
            'must be >= 0, null or "inf", got -1',
        ),
        (
            {"right": {"points": [[1, 0], [1, 1]], "mu": ["Infinity"]}},
            "right.mu[0]",
            'must be >= 0, null or "inf", got "Infinity"',
        ),
        (
            {"right": {"points": [[1, 0], [1, 1]], "mu": [math.nan]}},
            "right.mu[0]",
            'must be >= 0, null or "inf", got NaN',
        ),
    ],
)
def test_each_mistake_is_named(changes, field, message):
    error = _error(_document(**changes))
    assert (error.field, error.message) == (field, message)


def test_a_missing_part_is_named():
    for key, message in (("units", 'is required: "l0" (leg lengths) or "m" (metres)'),
                         ("right", 'is required: {"points": [[x, y], ...], "mu": [...]}')):  # fmt: skip
        document = _document()
        del document[key]
        assert (_error(document).field, _error(document).message) == (key, message)
    assert _error([1, 2]).field == "world"


def test_sides_that_cross_are_refused_in_the_files_units():
    error = _error(_document(units="m", right={"points": [[1.2, 0.0], [-1.4, 0.5]]}), L0_M)
    assert error.field == "left.points[1]", "a height where both sides have a vertex is named by the left one"
    assert "at y = 0.5 the left side is at x = -1.3, the right side at x = -1.4" in error.message


def test_metres_need_a_positive_l0():
    assert _error(_document(units="m")).field == "l0_m"
    error = _error(_document(units="m"), l0_m=-0.2)
    assert (error.field, error.message) == ("l0_m", "must be in (0, inf), got -0.2")


@pytest.mark.parametrize("units", ["l0", "m"])
def test_a_world_round_trips_through_its_document(units):
    world = world_from_document(_document())
    document = world_to_document(world, units, L0_M, description="a bend")
    assert document["units"] == units and document["description"] == "a bend"
    back = world_from_document(json.loads(json.dumps(document)), L0_M)
    if units == "l0":
        _same(back, world)
        assert world_to_document(back) == _document(), "a document in l0 comes back as written"
    else:
        assert_allclose(back.left.points, world.left.points, rtol=RTOL_METRES, atol=1e-15)
        assert_array_equal(back.right.mu, world.right.mu)


def test_writing_checks_the_world_first():
    bad = parallel(-2.0)  # the sides swapped: left of right nowhere
    with pytest.raises(ParameterError, match="the sides must not cross or touch"):
        world_to_document(bad)
    with pytest.raises(ParameterError) as raised:
        world_to_document(parallel(2.0), "ft")
    assert raised.value.field == "units"


def test_save_and_load(tmp_path):
    world = world_from_document(_document(name="bend"))
    path = tmp_path / "bend.json"
    save_world(world, path, "m", L0_M, description="a bend")
    first = f"[{-1.2 * L0_M!r}, 0.0]"
    assert f"\n      {first},\n" in path.read_text(), "a point on one line, in metres"
    back = load_world(path, L0_M)
    assert_allclose(back.left.points, world.left.points, rtol=RTOL_METRES)
    assert read_document(path)["description"] == "a bend"
    unnamed = world_from_document(_document(name=""))
    save_world(unnamed, tmp_path / "mine.json")
    assert load_world(tmp_path / "mine.json").name == "mine", "named after its file"


def test_a_file_that_is_not_json_is_named(tmp_path):
    path = tmp_path / "broken.json"
    path.write_text('{"units": "l0",')
    with pytest.raises(ParameterError) as raised:
        load_world(path)
    assert raised.value.field == str(path) and raised.value.message.startswith("is not JSON: ")
    with pytest.raises(OSError):
        load_world(tmp_path / "absent.json")


KEYS = st.sampled_from(["units", "left", "right", "points", "mu", "x"])
JSON = st.recursive(
    st.none() | st.booleans() | st.integers() | st.floats() | st.text(max_size=4) | st.just("inf"),
    lambda inner: st.lists(inner, max_size=4) | st.dictionaries(KEYS, inner, max_size=4),
    max_leaves=20,
)


@settings(max_examples=300, deadline=None)
@given(document=JSON)
def test_anything_else_is_refused_with_a_parameter_error(document):
    try:
        world = world_from_document(document, L0_M)
    except ParameterError:
        return
    assert isinstance(world, World)


@settings(max_examples=100, deadline=None)
@given(
    left=st.lists(st.tuples(st.floats(-3, -0.1), st.floats(0.01, 1)), min_size=1, max_size=8),
    mu=st.lists(st.one_of(st.none(), st.just("inf"), st.floats(0, 10)), min_size=8, max_size=8),
)
def test_any_valid_document_round_trips_exactly_in_l0(left, mu):
    y = np.cumsum([0.0] + [rise for _, rise in left])
    points = [[-2.0, 0.0]] + [[x, float(height)] for (x, _), height in zip(left, y[1:], strict=True)]
    document = {"units": "l0", "left": {"points": points, "mu": mu[: len(left)]},
                "right": {"points": [[1.0, 0.0], [1.0, 1.0]], "mu": [None]}}  # fmt: skip
    assert world_to_document(world_from_document(document)) == document
