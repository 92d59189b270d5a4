"""``parkour climb`` (cli/climb.py): the --json contract of issue 41, parallel walls as the map,
every named world, world files, and mistakes as one line naming the field, exit 2."""

from __future__ import annotations

import json

import numpy as np
import pytest

from sim_core.world.named import NAMED_WORLDS
from tests.cli.helpers import invoke, json_of, one_line_error

TOUCHDOWN_KEYS = {"jump", "side", "segment", "x", "y", "xdot", "ydot"}


def test_the_json_contract_and_parallel_walls_as_parkour_map():
    args = ("--controls", "30:0.87,30:0.9", "--state", "-1.2", "0.3", "--jumps", "8")
    climb = json_of("climb", "--world", "parallel", *args)
    assert set(climb) == {"touchdowns", "failure"} and climb["failure"] is None
    touchdowns = climb["touchdowns"]
    assert [set(row) for row in touchdowns] == [TOUCHDOWN_KEYS] * 9
    assert [row["jump"] for row in touchdowns] == list(range(9))
    assert [row["side"] for row in touchdowns] == ["left", "right"] * 4 + ["left"]
    mapped = json_of("map", *args)
    for row, (xdot, ydot) in zip(touchdowns, mapped["states"], strict=True):
        flip = 1.0 if row["side"] == "left" else -1.0
        assert flip * row["xdot"] == pytest.approx(xdot, abs=1e-10) and row["ydot"] == pytest.approx(ydot, abs=1e-10)
    feet = [row["y"] - 0.87 * 0.5 if k % 2 == 0 else row["y"] - 0.9 * 0.5 for k, row in enumerate(touchdowns)]
    assert feet[0] == pytest.approx(0.0, abs=1e-12), "touchdown 0's foot at --foot-y, default 0"
    assert list(np.diff(feet)) == pytest.approx(mapped["rises"], abs=1e-10)


@pytest.mark.parametrize("name", list(NAMED_WORLDS))
def test_every_named_world_climbs_or_says_why_not(name):
    climb = json_of("climb", "--world", name, "--state", "-1.0", "0.5", "--jumps", "12", "--foot-y", "0.1")
    failure = climb["failure"]
    assert failure is None or (set(failure) == {"code", "jump"} and failure["jump"] == len(climb["touchdowns"]))
    assert climb["touchdowns"][0]["y"] == pytest.approx(0.1 + 0.9 * 0.5)


def test_a_failure_is_numbered_from_one_and_named_by_its_code(tmp_path):
    greasy = {"units": "l0", "left": {"points": [[-1.21, -1], [-1.21, 9]], "mu": [0]},
              "right": {"points": [[1.21, -1], [1.21, 9]]}}  # fmt: skip
    path = tmp_path / "greasy.json"
    path.write_text(json.dumps(greasy))
    climb = json_of("climb", "--world", str(path), "--state", "-1.0", "0.5", "--jumps", "5")
    assert climb["failure"] == {"code": "slip", "jump": 1} and len(climb["touchdowns"]) == 1
    text = invoke("climb", "--world", str(path), "--state", "-1.0", "0.5", "--jumps", "5").stdout
    assert "failed at jump 1: slip" in text


def test_mistakes_are_one_line_naming_the_field(tmp_path):
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps({"units": "l0", "left": {"points": [[-1, 0], [-1, 2], [-1, 1]]},
                               "right": {"points": [[1, 0], [1, 2]]}}))  # fmt: skip
    assert "left.points[2]" in one_line_error("climb", "--world", str(bad), "--state", "-1", "0.5")
    assert "world" in one_line_error("climb", "--world", "moon", "--state", "-1", "0.5")
    assert "xdot" in one_line_error("climb", "--world", "parallel", "--state", "1", "0.5")
    assert "foot_y" in one_line_error("climb", "--world", "parallel", "--state", "-1", "0.5", "--foot-y", "nan")
    missing = one_line_error("climb", "--world", str(tmp_path / "none.json"), "--state", "-1", "0.5")
    assert "none.json" in missing


def test_noise_and_the_floor_only_when_asked():
    args = ("climb", "--world", "narrowing", "--state", "-1.0", "0.5", "--jumps", "10")
    assert json_of(*args) == json_of(*args, "--noise-psi0", "2.0"), "noise options alone apply no noise"
    noisy = json_of(*args, "--noise", "--seed", "4")
    assert noisy != json_of(*args) and noisy == json_of(*args, "--noise", "--seed", "4")
    descending = ("climb", "--world", "parallel", "--controls", "30:0.97", "--state", "-1.0", "0.0", "--jumps", "30")
    free = json_of(*descending)
    assert min(row["y"] for row in free["touchdowns"]) < 0.0, "without --floor it goes below it"
    cut = json_of(*descending, "--floor")
    assert cut["failure"] == {"code": "floor", "jump": 2} and all(row["y"] >= 0.0 for row in cut["touchdowns"])
