"""``parkour map`` and ``parkour trajectory`` (cli/simulate.py): their JSON and files."""

import csv
import json

import pytest

from tests.cli.helpers import invoke, json_of


def test_map_json_contract():
    payload = json_of("map", "--controls", "30:0.9", "--state", "-0.93", "-0.17", "--jumps", "4")
    assert set(payload) == {"states", "rises", "failure"}
    assert payload["states"][0] == [-0.93, -0.17] and len(payload["states"]) == 5
    assert len(payload["rises"]) == 4 and payload["failure"] is None


def test_map_json_reports_failure():
    result = invoke("map", "--state", "-0.3", "5", "--jumps", "3", "--json")
    payload = json.loads(result.stdout)
    assert payload["failure"] == {"code": "no_flight", "jump": 1}
    assert payload["states"] == [[-0.3, 5.0]] and payload["rises"] == []


@pytest.mark.parametrize("suffix", [".csv", ".json"])
def test_trajectory_writes_file(tmp_path, suffix):
    out = tmp_path / f"path{suffix}"
    summary = json_of("trajectory", "--state", "-0.93", "-0.17", "--jumps", "3", "--out", str(out))
    assert summary["jumps_completed"] == 3 and summary["units"] == "SI"
    if suffix == ".csv":
        rows = list(csv.DictReader(out.open()))
        assert len(rows) == summary["samples"] and set(rows[0]) >= {"time", "x", "y", "phase"}
    else:
        document = json.loads(out.read_text())
        assert len(document["columns"]["time"]) == summary["samples"]


def test_trajectory_json_is_strict_json_with_infinite_friction(tmp_path):
    out = tmp_path / "path.json"
    result = invoke("trajectory", "--state", "-0.93", "-0.17", "--jumps", "1", "--mu", "inf", "--out", str(out))
    assert result.exit_code == 0, result.output
    document = json.loads(out.read_text(), parse_constant=lambda name: pytest.fail(f"non-JSON constant {name}"))
    assert document["model"]["mu"] is None
