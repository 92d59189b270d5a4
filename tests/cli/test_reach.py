"""``parkour reach`` (cli/reach.py) and ``parkour mjtf --world``: their JSON, and mistakes as one
line naming the option, exit 2."""

from __future__ import annotations

from sim_core.world.reach import TOP
from tests.cli.helpers import invoke, json_of

GRID = ("--psi0-range", "25", "35", "--psi0-steps", "3", "--zeta0-range", "0.86", "0.92", "--zeta0-steps", "2")


def test_reach_json_is_the_grid_row_by_zeta0():
    reach = json_of("reach", "--world", "narrowing", "--state", "-1.0", "0.5", *GRID, "--jumps", "30")
    assert set(reach) == {"world", "state", "foot_y", "jumps", "top", "psi0_deg", "zeta0", "highest", "last",
                          "completed", "ending", "outcomes", "l0_m"}  # fmt: skip
    assert reach["world"] == "narrowing" and reach["psi0_deg"] == [25.0, 30.0, 35.0] and reach["zeta0"] == [0.86, 0.92]
    assert [len(row) for row in reach["ending"]] == [3, 3] and sum(reach["outcomes"].values()) == 6
    assert reach["outcomes"][TOP] == sum(row.count(TOP) for row in reach["ending"])
    assert "reach in narrowing" in invoke("reach", "--world", "narrowing", "--state", "-1.0", "0.5", *GRID).stdout


def test_mjtf_in_a_world_names_it():
    study = json_of("mjtf", "--world", "widening", "--foot-y", "0.2", "--zeta0", "0.9", "--trials", "3", "--cap", "20")
    assert study["world"] == "widening" and study["foot_y"] == 0.2 and study["levels"][0]["trials"] == 3


def test_mistakes_name_the_option():
    for args, named in (
        (("reach", "--world", "narrowing", "--state", "-1", "0.5", "--psi0-steps", "0"), "--psi0-steps"),
        (("reach", "--world", "mars", "--state", "-1", "0.5"), "world"),
        (("mjtf", "--foot-y", "1", "--zeta0", "0.9"), "--foot-y"),
    ):
        result = invoke(*args)
        assert result.exit_code == 2 and named in result.stderr and len(result.stderr.strip().splitlines()) == 1, (
            args,
            result.output,
        )
