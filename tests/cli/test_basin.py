"""``parkour basin`` (cli/basin.py): the JSON contract."""

from tests.cli.helpers import json_of


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
