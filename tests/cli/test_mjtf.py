"""``parkour mjtf`` (cli/mjtf.py): the JSON contract."""

from tests.cli.helpers import json_of


def test_mjtf_json_contract():
    args = [
        "--zeta0-range",
        "0.88",
        "0.92",
        "--levels",
        "2",
        "--trials",
        "3",
        "--cap",
        "30",
        "--guess",
        "-0.93",
        "-0.2",
    ]
    payload = json_of("mjtf", *args, "--seed", "3")
    assert set(payload) == {"psi0_deg", "fixed_leg", "noise", "trials", "cap", "seed", "levels"}
    level = payload["levels"][0]
    assert set(level) == {"zeta0", "energy", "start", "trials", "mean", "std", "ci95", "outcomes", "jumps"}
    assert level["trials"] == 3 and sum(level["outcomes"].values()) == 3
    again = json_of("mjtf", *args, "--seed", "3")
    assert again == payload, "seeded"
