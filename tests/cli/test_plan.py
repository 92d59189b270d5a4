"""``parkour plan`` (cli/plan.py): the contract of issue 42, no way up as one line naming the
highest reachable height (exit 2), goals out of the world refused in metres."""

from sim_core.model.presets import get_preset
from tests.cli.helpers import json_of, one_line_error

ARGS = ("plan", "--world", "staircase", "--state", "-1.0", "0.5")


def test_the_plan_json_contract():
    plan = json_of(*ARGS, "--goal-height", "1.0")
    assert set(plan) >= {"reaches_goal", "plan", "seconds", "highest_m"} and plan["reaches_goal"] is True
    keys = {"jump", "side", "segment", "target", "psi0_deg", "zeta0", "velocity"}  # velocity: issue 43 (live runs)
    assert all(set(row) == keys for row in plan["plan"])
    assert [row["jump"] for row in plan["plan"]] == list(range(len(plan["plan"])))
    last = plan["plan"][-1]["target"][1] * get_preset("paper").leg_length
    assert last >= 1.0 and plan["highest_m"] >= last - 1e-9


def test_no_way_up_and_goals_out_of_the_world_are_one_line(tmp_path):
    greasy = tmp_path / "greasy.json"
    greasy.write_text('{"units": "l0", "left": {"points": [[-1.21, 0], [-1.21, 1], [-1.21, 9]], "mu": [null, 0]},'
                      ' "right": {"points": [[1.21, 0], [1.21, 1], [1.21, 9]], "mu": [null, 0]}}')  # fmt: skip
    said = one_line_error("plan", "--world", str(greasy), "--state", "-1.0", "0.5", "--goal-height", "1.5")
    assert "no plan reaches 1.5 m" in said and "highest reachable is 0.2" in said
    assert "--goal-height" in one_line_error(*ARGS, "--goal-height", "5")


def test_the_mfpt_of_a_plan_by_splitting_with_monte_carlo_beside_it():
    plan = json_of(*ARGS, "--goal-height", "1.0", "--mfpt", "--replicas", "10", "--runs", "3", "--replans", "0",
                   "--monte-carlo", "200")  # fmt: skip
    mfpt = plan["mfpt"]
    assert mfpt["method"] == "splitting" and set(mfpt) >= {
        "failure_chance", "failure_chance_ci95", "mean_attempt_jumps", "mfpt_jumps", "ci95", "splitting", "seconds",
        "monte_carlo"}  # fmt: skip
    assert mfpt["splitting"]["runs"] == 3 and len(mfpt["splitting"]["runs_failure_chance"]) == 3
    check = mfpt["monte_carlo"]
    assert check["trials"] == 200 and 0 <= check["failures"] <= 200
    low, high = check["failure_chance_ci95"]
    assert low <= check["failure_chance"] <= high
    if mfpt["failure_chance"] > 0:
        assert mfpt["mfpt_jumps"] == mfpt["mean_attempt_jumps"] / mfpt["failure_chance"]


def test_mfpt_options_are_checked_naming_the_option():
    assert "--replicas: needs --mfpt" in one_line_error(*ARGS, "--goal-height", "1.0", "--replicas", "10")
    assert "--replicas" in one_line_error(*ARGS, "--goal-height", "1.0", "--mfpt", "--replicas", "1")
    assert "--monte-carlo" in one_line_error(*ARGS, "--goal-height", "1.0", "--mfpt", "--monte-carlo", "0")
    assert "--replans" in one_line_error(*ARGS, "--goal-height", "1.0", "--mfpt", "--replans", "-1")


def test_importance_sampling_beside_the_mfpt():
    """Its object beside Monte-Carlo's (whose keys stay as they were), the options as asked."""
    plan = json_of(*ARGS, "--goal-height", "1.0", "--mfpt", "--replicas", "2", "--runs", "2", "--replans", "0",
                   "--monte-carlo", "20", "--importance-sampling", "200", "--is-scale", "2", "--is-draws",
                   "psi0,zeta0", "--is-first-leg")  # fmt: skip
    mfpt = plan["mfpt"]
    assert set(mfpt["monte_carlo"]) == {"trials", "failures", "failure_chance", "failure_chance_ci95",
                                        "mean_attempt_jumps", "mfpt_jumps", "seconds"}  # fmt: skip
    sampled = mfpt["importance_sampling"]
    assert set(sampled) == {
        "trials", "scale", "scaled", "first_leg_only", "failures_under_proposal", "failure_chance", "standard_error",
        "relative_error", "failure_chance_ci95", "effective_sample_size", "effective_failures",
        "mean_attempt_jumps", "mfpt_jumps", "warning", "seconds"}  # fmt: skip
    assert (sampled["trials"], sampled["scale"], sampled["scaled"], sampled["first_leg_only"]) == (
        200, 2.0, ["psi0", "zeta0"], True)  # fmt: skip
    assert 0 <= sampled["failures_under_proposal"] <= 200 and 0 < sampled["effective_sample_size"] <= 200
    low, high = sampled["failure_chance_ci95"]
    assert low <= sampled["failure_chance"] and (high is None or sampled["failure_chance"] <= high)


def test_importance_sampling_options_are_checked_naming_the_option():
    mfpt = (*ARGS, "--goal-height", "1.0", "--mfpt")
    assert "--importance-sampling: needs --mfpt" in one_line_error(*ARGS, "--goal-height", "1.0",
                                                                   "--importance-sampling", "10")  # fmt: skip
    assert "--is-scale: needs --importance-sampling" in one_line_error(*mfpt, "--is-scale", "2")
    assert "--is-first-leg: needs --importance-sampling" in one_line_error(*mfpt, "--is-first-leg")
    assert "--importance-sampling: must be in" in one_line_error(*mfpt, "--importance-sampling", "1")
    for scale in ("0.5", "6", "nan"):
        assert "--is-scale" in one_line_error(*mfpt, "--importance-sampling", "10", "--is-scale", scale)
    said = one_line_error(*mfpt, "--importance-sampling", "10", "--is-draws", "psi0,yaw")
    assert "--is-draws" in said and "psi0, zeta0, velocity, pitch" in said
