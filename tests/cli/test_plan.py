"""``parkour plan`` (cli/plan.py): the contract of issue 42, no way up as one line naming the
highest reachable height (exit 2), goals out of the world refused in metres."""

from sim_core.model.presets import get_preset
from tests.cli.helpers import json_of, one_line_error

ARGS = ("plan", "--world", "staircase", "--state", "-1.0", "0.5")


def test_the_plan_json_contract():
    plan = json_of(*ARGS, "--goal-height", "1.0")
    assert set(plan) >= {"reaches_goal", "plan", "seconds", "highest_m"} and plan["reaches_goal"] is True
    assert all(set(row) == {"jump", "side", "segment", "target", "psi0_deg", "zeta0"} for row in plan["plan"])
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
