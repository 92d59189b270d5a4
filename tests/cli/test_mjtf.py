"""``parkour mjtf`` (cli/mjtf.py): the JSON contract."""

from tests.cli.helpers import invoke, json_of


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


def test_one_level_by_zeta0_is_the_ranges_first_level():
    """``--zeta0 Z``: a single level (the range needs two); its trials are the range's at that level."""
    common = ("--trials", "4", "--cap", "100", "--seed", "3")
    alone = json_of("mjtf", "--zeta0", "0.88", *common)
    in_range = json_of("mjtf", "--zeta0-range", "0.88", "0.9", "--levels", "2", *common)
    assert len(alone["levels"]) == 1 and alone["levels"][0] == in_range["levels"][0]


def test_levels_given_twice_or_out_of_range_are_refused_naming_the_option():
    for args, words in ((("--zeta0", "0.9", "--zeta0", "0.9"), "each level once"), (("--zeta0", "1.2"), "(0, 1)")):
        result = invoke("mjtf", *args)
        assert result.exit_code == 2 and "--zeta0" in result.output and words in result.output
