"""``parkour sweep`` (cli/sweep.py): the JSON contract."""

from tests.cli.helpers import json_of


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
