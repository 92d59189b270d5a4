"""``parkour foothold-study`` (cli/foothold.py): the contract of issue 42 — methods and world rows
exactly as specified — and bad input as one line naming the option."""

from sim_core.model.presets import get_preset
from tests.cli.helpers import json_of, one_line_error

METHOD_KEYS = {"reached", "trials", "failures_by_code", "mean_jumps", "plan_seconds_median", "law_us_per_jump"}
ARGS = ("foothold-study", "--goal-height", "0.6", "--trials", "3", "--state", "-1.0", "0.5")


def test_the_foothold_study_json_contract():
    study = json_of(*ARGS, "--random", "2", "--seed0", "4", "--seed", "11")
    assert set(study) >= {"methods", "worlds"} and set(study["methods"]) == {"open-loop", "placement"}
    for method in study["methods"].values():
        assert set(method) >= METHOD_KEYS and method["trials"] == 6
        assert method["reached"] + sum(method["failures_by_code"].values()) == 6
    assert study["methods"]["placement"]["law_us_per_jump"] > 0.0
    assert [row["world"] for row in study["worlds"]] == ["random:4", "random:5"]
    for row in study["worlds"]:
        assert set(row) == {"world", "plan_exists", "trials", "reached"} and row["trials"] == 3
        assert set(row["reached"]) == {"open-loop", "placement"}
    assert sum(row["reached"]["placement"] for row in study["worlds"]) == study["methods"]["placement"]["reached"]


def test_bad_input_is_one_line_naming_the_option(tmp_path):
    greasy = tmp_path / "greasy.json"
    greasy.write_text('{"units": "l0", "left": {"points": [[-1.21, 0], [-1.21, 1], [-1.21, 9]], "mu": [null, 0]},'
                      ' "right": {"points": [[1.21, 0], [1.21, 1], [1.21, 9]], "mu": [null, 0]}}')  # fmt: skip
    bare = tmp_path / "bare.json"
    bare.write_text('{"units": "l0", "left": {"points": [[-1.21, 0], [-1.21, 9]], "mu": [0]},'
                    ' "right": {"points": [[1.21, 0], [1.21, 9]], "mu": [0]}}')  # fmt: skip
    above = one_line_error("foothold-study", "--worlds", str(greasy), "--goal-height", "1.5", "--trials", "3")
    l0 = get_preset("paper").leg_length  # greasy's highest foothold tops at 1 l0
    assert "--goal-height" in above and f"highest foothold ({l0:.3f} m)" in above
    study = ("foothold-study", "--trials", "3")
    assert "no foothold" in one_line_error(*study, "--worlds", str(bare), "--goal-height", "1")
    below = one_line_error("foothold-study", "--worlds", "staircase", "--goal-height", "-0.1", "--trials", "3")
    assert "--goal-height" in below and "above the start" in below
    both = one_line_error(*study, "--worlds", "staircase", "--random", "2", "--goal-height", "1")
    assert "--worlds" in both
    assert "--trials" in one_line_error("foothold-study", "--random", "1", "--goal-height", "1", "--trials", "0")
    assert "--hold-mu" in one_line_error("foothold-study", "--random", "1", "--goal-height", "1", "--trials", "2",
                                         "--hold-mu", "2", "1")  # fmt: skip
