"""``parkour world list|show|random`` (cli/world.py): the --json contracts, world files that load
back, and mistakes as one line naming the field, exit 2."""

from __future__ import annotations

import json

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

from sim_core.world.files import load_world, save_world
from sim_core.world.named import NAMED_WORLDS, named_world
from sim_core.world.world import parallel
from tests.cli.helpers import invoke, json_of, one_line_error


def test_list_names_every_world_with_its_description():
    listed = json_of("world", "list")
    assert listed == [{"name": name, "description": entry.description} for name, entry in NAMED_WORLDS.items()]
    text = invoke("world", "list").stdout
    assert all(name in text for name in NAMED_WORLDS)


@pytest.mark.parametrize("name", list(NAMED_WORLDS))
def test_show_prints_a_named_world_as_its_file_in_l0(name, tmp_path):
    document = json_of("world", "show", name)
    assert document["units"] == "l0" and document["name"] == name
    assert document["description"] == NAMED_WORLDS[name].description
    path = tmp_path / "shown.json"
    path.write_text(json.dumps(document))
    assert_array_equal(load_world(path).right.points, named_world(name, 2.42).right.points)


def test_show_builds_for_the_chutes_width():
    document = json_of("world", "show", "parallel", "--d-hat", "3")
    assert document["left"]["points"][0][0] == -1.5 and document["right"]["mu"] == [None]


def test_show_reads_a_file_in_metres_with_the_presets_l0(tmp_path):
    path = tmp_path / "walls.json"
    save_world(parallel(2.0, height=4.0), path, "m", 0.25, description="two walls")
    document = json_of("world", "show", str(path))
    assert document["name"] == "parallel" and document["description"] == "two walls"
    paper_l0 = 0.54 / 2.42
    assert_allclose(document["left"]["points"], [[-0.25 / paper_l0, 0], [-0.25 / paper_l0, 1 / paper_l0]], rtol=1e-14)


def test_show_as_a_table_gives_each_segments_beta_and_mu():
    text = invoke("world", "show", "staircase").stdout
    lines = text.splitlines()
    assert lines[0].startswith("world staircase, in l0: Steps") and "beta deg" in lines[1]
    first, second = lines[2].split(), lines[3].split()
    assert first[:2] == ["left", "0"] and first[-2:] == ["+20.00", "model's"], "a step: 20° up, the model's mu"
    assert second[:2] == ["left", "1"] and second[-1] == "0", "between steps: no grip"
    assert lines[-1].startswith("Below its first point and above its last")


def test_random_writes_a_world_file_and_reports_it(tmp_path):
    out = tmp_path / "course.json"
    args = ("world", "random", "--seed", "5", "--holds", "6", "--incline-deg", "0", "20", "--mu", "1", "1.5")
    printed = json_of(*args, "--gap", "0.2", "0.3", "--out", str(out))
    world = load_world(out)
    assert printed == {"out": str(out), "name": "random-5", "segments": {"left": 12, "right": 12}}
    assert world.name == "random-5" and world.left.segments == 12
    gripping = world.left.mu[world.left.mu > 0]
    assert len(gripping) == 6 and np.all((gripping >= 1) & (gripping <= 1.5))
    assert "seed 5" in json.loads(out.read_text())["description"]
    again = tmp_path / "again.json"
    json_of(*args, "--gap", "0.2", "0.3", "--out", str(again))
    assert again.read_text().replace("again", "course") == out.read_text(), "the same seed, the same file"


def test_random_defaults_fill_the_lab_chute(tmp_path):
    out = tmp_path / "default.json"
    result = invoke("world", "random", "--out", str(out))
    assert result.exit_code == 0 and result.stdout.startswith(f"wrote {out}: random-0")
    world = load_world(out)
    assert world.left.points[-1, 1] == pytest.approx(2.0 / (0.54 / 2.42))
    assert world.right.x_at(0.0) - world.left.x_at(0.0) == pytest.approx(2.42, abs=0.4)


@pytest.mark.parametrize(
    ("args", "said"),
    [
        (("random", "--incline-deg", "-85", "10"), "error: --incline-deg: must be in (-80, 80), got -85"),
        (("random", "--mu", "2", "1"), "error: --mu: must be an interval (low, high) with low <= high, got (2, 1)"),
        (("random", "--gap", "0", "0.2"), "error: --gap: must be in (0, inf), got 0"),
        (("random", "--holds", "0"), "error: --holds: must be in [1, 128] per side (MAX_HOLDS), got 0"),
        (("random", "--seed", "-3"), "error: --seed: must be an integer >= 0, got -3"),
        (("random", "--d-hat", "0.1"), "error: --d-hat: must be > 0.2 l0 so that footholds on the two sides"),
        (("show", "maze"), "error: world: 'maze' is neither a named world (parallel, narrowing, widening, staircase)"),
        (("show", "parallel", "--d-hat", "-1"), "error: d_hat: must be in (0, inf), got -1"),
    ],
)
def test_mistakes_are_one_line_naming_the_field(args, said, tmp_path):
    extra = ("--out", str(tmp_path / "x.json")) if args[0] == "random" else ()
    assert one_line_error("world", *args, *extra).startswith(said)
    assert not (tmp_path / "x.json").exists(), "nothing written"


def test_a_bad_world_file_is_one_line_naming_the_point(tmp_path):
    path = tmp_path / "bad.json"
    bad = {"units": "l0", "left": {"points": [[-1, 0], [-1, 0.9], [-1, 0.8]]}, "right": {"points": [[1, 0], [1, 1]]}}
    path.write_text(json.dumps(bad))
    said = one_line_error("world", "show", str(path))
    assert said == "error: left.points[2]: y must increase strictly bottom to top: 0.8 after 0.9"
    path.write_text("{")
    assert one_line_error("world", "show", str(path)).startswith(f"error: {path}: is not JSON: ")
    assert "No such file" in one_line_error("world", "show", str(tmp_path / "absent.json"))
