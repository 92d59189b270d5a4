"""The ``parkour`` command-line contract: JSON shapes scripts rely on, and one-line errors."""

import csv
import json

import pytest
from typer.testing import CliRunner

from cli.app import app
from tests.sim_core.test_bench import CONTRACT as BENCH_CONTRACT
from tests.sim_core.test_fixed_points import GAIT_KEYS  # one gait in fixed-point and gaits --json

runner = CliRunner()


def invoke(*args: str):
    return runner.invoke(app, list(args))


def json_of(*args: str):
    """The command's JSON on stdout, after checking it succeeded."""
    result = invoke(*args, "--json")
    assert result.exit_code == 0, result.output
    return json.loads(result.stdout)


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


def test_fixed_point_json_contract():
    payload = json_of("fixed-point", "--controls", "30:0.87,30:0.9", "--period", "2", "--guess", "-0.8", "-0.15")
    assert list(payload) == GAIT_KEYS, "orbit and motion joined the original seven keys, at the end"
    assert payload["period"] == 2 and payload["stable"] is True
    assert len(payload["orbit"]) == 2 and payload["orbit"][0] == payload["state"] and payload["motion"] == "climbing"
    assert len(payload["eigenvalues"]) == 2 and all(len(pair) == 2 for pair in payload["eigenvalues"])
    assert payload["residual"] < 1e-9


def test_fixed_point_without_guess_searches():
    assert json_of("fixed-point")["stable"] is True


def test_fixed_point_without_any_gait_says_so_in_one_line():
    result = invoke("fixed-point", "--controls", "80:0.99")
    assert result.exit_code == 2
    assert result.stderr == "error: no period-1 gait found for controls 80°:0.99; give a starting state explicitly\n"


def test_gaits_lists_motion():
    gaits = json_of("gaits", "--controls", "30:0.98", "--grid", "3")["gaits"]
    assert gaits and all(gait["motion"] in {"climbing", "in place", "descending"} for gait in gaits)
    assert all(list(gait) == GAIT_KEYS for gait in gaits)


def test_model_overrides_change_the_result():
    base = json_of("map", "--state", "-0.93", "-0.17", "--jumps", "1")
    stiffer = json_of("map", "--state", "-0.93", "-0.17", "--jumps", "1", "--alpha", "90")
    assert stiffer["states"][1] != base["states"][1]


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


@pytest.mark.parametrize(
    ("args", "field"),
    [
        (["map", "--controls", "30:1.0", "--state", "-1", "0"], "zeta0"),
        (["map", "--controls", "95:0.9", "--state", "-1", "0"], "psi0"),
        (["map", "--controls", "0:0.9", "--state", "-1", "0"], "psi0"),
        (["map", "--state", "nan", "0"], "state.xdot"),
        (["map", "--state", "0.5", "0"], "state.xdot"),
        (["map", "--alpha", "-3", "--state", "-1", "0"], "alpha"),
        (["map", "--preset", "moon", "--state", "-1", "0"], "preset"),
        (["map", "--controls", "30-0.9", "--state", "-1", "0"], "controls"),
        (["fixed-point", "--controls", "30:0.87,30:0.9", "--period", "3"], "period"),
        (["trajectory", "--out", "x.txt"], "out"),
        (["basin", "--grid", "1000000000"], "grid"),
        (["basin", "--xdot-range", "-0.5", "-1.5"], "xdot_range"),
        (["basin", "--tolerance", "-1"], "tolerance"),
        (["basin", "--jumps", "-5"], "jumps"),
        (["sweep", "--zeta0-range", "0.9", "0.8"], "zeta0_range"),
        (["sweep", "--steps", "0"], "steps"),
        (["sweep", "--fixed-leg", "30:0.9,30:0.8"], "fixed_leg"),
        (["sweep", "--basin-grid", "1"], "grid"),
        (["mjtf", "--trials", "-1"], "trials"),
        (["mjtf", "--cap", "0"], "cap"),
        (["mjtf", "--noise-psi0", "-1"], "noise.psi0_deg"),
        (["mjtf", "--seed", "-1"], "seed"),
        (["pid", "--seed", "-1"], "seed"),
        (["pid", "--kp", "-1"], "kp"),
        (["pid", "--zeta0-min", "0.97", "--zeta0-max", "0.9"], "zeta0_max"),
        (["pid", "--target", "0"], "target"),
        (["atlas", "--psi0-range", "40", "20"], "psi0_range"),
        (["atlas", "--plot", "map.pdf"], "plot"),
        (["reproduce", "fig99", "--out", "x"], "figure"),
    ],
)
def test_bad_input_is_one_clear_line(args, field):
    result = invoke(*args)
    assert result.exit_code == 2
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"error: {field}:"), result.stderr
    assert "Traceback" not in result.output


def test_basin_json_contract():
    args = ["--controls", "30:0.9", "--guess", "-0.9", "-0.2", "--grid", "6", "--jumps", "20"]
    payload = json_of("basin", *args)
    assert set(payload) == {  # each command's keys spelled out (alike in shape only): the contract scripts read
        "gait",
        "xdot_range",
        "ydot_range",
        "grid",
        "jumps",
        "tolerance",
        "area",
        "fraction",
        "counts",
        "jumps_computed",
        "failure_codes",
        "jumps_to_converge",
        "failure",
    }
    assert payload["grid"] == 6 and len(payload["jumps_to_converge"]) == 6 and len(payload["failure"][0]) == 6
    assert sum(payload["counts"].values()) == 36 and payload["gait"]["period"] == 1


def test_sweep_json_contract():
    args = ["--psi0", "30", "--zeta0-range", "0.90", "0.97", "--steps", "3", "--guess", "-0.93", "-0.2"]
    payload = json_of("sweep", *args, "--basin-grid", "6")
    assert set(payload) == {"psi0_deg", "fixed_leg", "points", "in_place_zeta0", "basin"}
    assert [point["zeta0"] for point in payload["points"]] == [0.9, 0.935, 0.97]
    assert set(payload["points"][0]) == {
        "zeta0",
        "energy",
        "found",
        "state",
        "period",
        "max_abs_eigenvalue",
        "stable",
        "climb_per_jump",
        "basin_area",
    }
    assert len(payload["in_place_zeta0"]) == 1 and payload["basin"]["grid"] == 6


def test_mjtf_json_contract():
    args = [
        "--zeta0-range",
        "0.88",
        "0.92",
        "--levels",
        "2",
        "--trials",
        "3",
        "--cap",
        "30",
        "--guess",
        "-0.93",
        "-0.2",
    ]
    payload = json_of("mjtf", *args, "--seed", "3")
    assert set(payload) == {"psi0_deg", "fixed_leg", "noise", "trials", "cap", "seed", "levels"}
    level = payload["levels"][0]
    assert set(level) == {"zeta0", "energy", "start", "trials", "mean", "std", "ci95", "outcomes", "jumps"}
    assert level["trials"] == 3 and sum(level["outcomes"].values()) == 3
    again = json_of("mjtf", *args, "--seed", "3")
    assert again == payload, "seeded"


def test_pid_json_contract():
    payload = json_of("pid", "--jumps", "40")
    assert set(payload) >= {
        "target",
        "gains",
        "zeta0_hover",
        "failure",
        "rise_time",
        "overshoot",
        "settling_jump",
        "steady_error",
        "time",
        "height",
        "zeta0",
        "si",
    }
    assert payload["si"]["target_m"] == 0.55 and len(payload["si"]["height_m"]) == 41


def test_atlas_json_contract(tmp_path):
    plot = tmp_path / "atlas.png"
    args = ["--psi0-range", "25", "35", "--zeta0-range", "0.88", "0.97", "--grid", "2", "3", "--plot", str(plot)]
    payload = json_of("atlas", *args)
    assert set(payload) == {
        "row_label",
        "column_label",
        "rows",
        "columns",
        "period",
        "climb_per_jump",
        "max_abs_eigenvalue",
        "count",
        "cells",
    }
    assert len(payload["period"]) == 2 and len(payload["period"][0]) == 3
    assert plot.read_bytes()[:4] == b"\x89PNG"


def test_bench_json_contract():
    sizes = ["--baseline-strides", "3", "--kernel-strides", "20", "--batch-strides", "20", "--repeats", "1"]
    payload = json_of("bench", *sizes, "--basin-grid", "4", "--basin-jumps", "5")
    assert set(payload) >= BENCH_CONTRACT
