"""``parkour pid`` (cli/pid.py): the JSON contract."""

from tests.cli.helpers import json_of


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
