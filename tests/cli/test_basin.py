"""``parkour basin`` (cli/basin.py): the JSON contract."""

from tests.cli.helpers import invoke, json_of

ARGS = ["--controls", "30:0.9", "--guess", "-0.9", "-0.2", "--grid", "6"]


def test_basin_json_contract():
    payload = json_of("basin", *ARGS, "--jumps", "20")
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
        "jump_limit",
        "undecided",
        "falling",
        "rounds",
        "failure_codes",
        "jumps_to_converge",
        "failure",
    }
    assert payload["grid"] == 6 and len(payload["jumps_to_converge"]) == 6 and len(payload["failure"][0]) == 6
    assert sum(payload["counts"].values()) == 36 and payload["gait"]["period"] == 1
    assert payload["jump_limit"] == 20 and payload["rounds"] == [
        {"cap": 20, "converged": payload["counts"]["converged"], "undecided": payload["undecided"]}
    ]


def test_jump_limit_continues_the_undecided_cells():
    payload = json_of("basin", *ARGS, "--jumps", "5", "--jump-limit", "30", "--summary")
    assert payload["jumps"] == 5 and payload["jump_limit"] == 30
    assert [r["cap"] for r in payload["rounds"]] == [5, 10, 20, 30]
    assert payload["rounds"][-1]["converged"] == payload["counts"]["converged"] > payload["rounds"][0]["converged"]
    assert payload["undecided"] == payload["counts"]["not_converged"] >= payload["falling"]


def test_a_limit_below_the_first_cap_is_refused_by_its_option():
    result = invoke("basin", *ARGS, "--jumps", "20", "--jump-limit", "10")
    assert result.exit_code == 2 and "error: --jump-limit: must be at least the first cap" in result.output
