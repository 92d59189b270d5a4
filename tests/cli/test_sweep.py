"""``parkour sweep`` (cli/sweep.py): the JSON contract."""

from tests.cli.helpers import invoke, json_of


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
        "basin_undecided",
    }
    assert len(payload["in_place_zeta0"]) == 1 and payload["basin"]["grid"] == 6
    assert payload["basin"]["jump_limit"] == payload["basin"]["jumps"] == 60


def test_sweep_basins_continue_up_to_the_jump_limit():
    args = ["--psi0", "30", "--zeta0-range", "0.93", "0.95", "--steps", "2", "--guess", "-0.93", "-0.2"]
    short = json_of("sweep", *args, "--basin-grid", "6", "--basin-jumps", "10")
    long = json_of("sweep", *args, "--basin-grid", "6", "--basin-jumps", "10", "--basin-jump-limit", "200")
    assert long["basin"]["jump_limit"] == 200
    for cut, continued in zip(short["points"], long["points"], strict=True):
        assert continued["basin_area"] >= cut["basin_area"] and continued["basin_undecided"] <= cut["basin_undecided"]
    assert long["points"][1]["basin_area"] > short["points"][1]["basin_area"], "10 jumps cut the basin short"


def test_a_basin_limit_below_the_first_cap_is_refused_by_its_option():
    result = invoke("sweep", "--steps", "2", "--basin-jumps", "20", "--basin-jump-limit", "10")
    assert result.exit_code == 2 and "error: --basin-jump-limit: must be at least the first cap" in result.output
