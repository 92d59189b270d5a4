"""What every command shares (cli/options.py): model overrides, and errors as one line naming the field."""

import pytest

from tests.cli.helpers import invoke, json_of


def test_model_overrides_change_the_result():
    base = json_of("map", "--state", "-0.93", "-0.17", "--jumps", "1")
    stiffer = json_of("map", "--state", "-0.93", "-0.17", "--jumps", "1", "--alpha", "90")
    assert stiffer["states"][1] != base["states"][1]


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
        (["sweep", "--basin-grid", "1"], "--basin-grid"),
        (["mjtf", "--trials", "-1"], "trials"),
        (["mjtf", "--cap", "0"], "cap"),
        (["mjtf", "--noise-psi0", "-1"], "noise.psi0_deg"),
        (["mjtf", "--seed", "-1"], "seed"),
        (["mjtf", "--levels", "1"], "--levels"),  # the library's name for it ("steps") is no option of mjtf
        (["atlas", "--grid", "13", "1"], "--grid COLUMNS"),
        (["atlas", "--grid", "1", "13"], "--grid ROWS"),
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
