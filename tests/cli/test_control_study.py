"""``parkour control-study`` (cli/control_study.py): the JSON contract of issue 27 and its errors."""

import pytest

from tests.cli.helpers import invoke, json_of

ENTRY = {"name", "trials", "failures", "failure_rate", "failure_codes", "height_rms_m", "height_median_abs_m",
         "rise_jumps", "us_per_jump", "saturated_fraction", "mean_jumps_to_failure", "mean_jumps_to_failure_ci95",
         "survived"}  # fmt: skip


def test_control_study_json_contract():
    payload = json_of("control-study", "--controllers", "pid,pid-pitch,lqr,deadbeat", "--target", "0.55",
                      "--seeds", "6", "--seed0", "3", "--jumps", "60", "--pitch-drift", "1.0")  # fmt: skip
    assert set(payload) == {"target_m", "jumps", "seeds", "noise", "controllers"}
    assert payload["target_m"] == 0.55 and payload["jumps"] == 60 and payload["seeds"] == [3, 6]
    assert payload["noise"]["pitch_drift_deg"] == 1.0
    assert [entry["name"] for entry in payload["controllers"]] == ["pid", "pid-pitch", "lqr", "deadbeat"]
    for entry in payload["controllers"]:
        assert set(entry) == ENTRY and entry["trials"] == 6
        assert entry["failure_rate"] == entry["failures"] / 6 and entry["us_per_jump"] > 0
        assert entry["survived"] == 6 - entry["failures"] and 0 < entry["mean_jumps_to_failure"] <= 60


@pytest.mark.parametrize(
    ("args", "says"),
    [
        (("--controllers", "mpc"), "controllers: must be among pid, pid-pitch, lqr, deadbeat, placement, got 'mpc'"),
        (("--controllers", "pid,pid"), "controllers: names a controller twice"),
        (("--controllers", " , "), "controllers: must name at least one"),
        (("--seeds", "0"), "seeds"),
        (("--target", "-1"), "target"),
        (("--target", "2.5"), "target: must be in (0, 2]"),
        (("--psi0", "80"), "psi0"),
    ],
)
def test_bad_input_is_one_line_naming_the_field(args, says):
    result = invoke("control-study", "--jumps", "10", "--seeds", "2", *args)
    assert result.exit_code == 2 and says in result.output and "Traceback" not in result.output
