"""``parkour viability`` (cli/viability.py): the JSON it prints and the errors a user can fix."""

import pytest

from tests.cli.helpers import invoke, json_of


def test_viability_json_holds_the_kernel_its_measure_and_a_states_actions():
    payload = json_of("viability", "--states", "10", "--actions", "5", "--state", "1.0", "0.5", "--json")
    assert {"kernel_fraction", "kernel_cells", "cells", "pairs", "measure_mean", "seconds"} <= set(payload)
    assert payload["cells"] == 100 and payload["pairs"] == 2500
    assert len(payload["kernel"]) == 10 and len(payload["measure"][0]) == 10
    assert payload["action_axes"]["psi0_deg"][0] == pytest.approx(15.0)
    chosen = payload["state"]
    assert chosen["in_kernel"] is (chosen["measure"] > 0)
    assert all(15 - 1e-9 <= psi0 <= 55 + 1e-9 and 0.7 <= zeta0 <= 0.98 for psi0, zeta0 in chosen["viable_actions"])
    assert len(chosen["viable_actions"]) == round(chosen["measure"] * 25)


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (("--states", "1"), "--states: must be an integer >= 2"),
        (("--xdot-range", "-1", "2"), "--xdot-range: must be in"),
        (("--pitch-nodes", "3"), "--pitch-deg: must be in"),
        (("--states", "3000", "--actions", "100"), "--states: must hold at most 50,000,000 state-action pairs"),
        (("--d-hat", "1.9"), "d_hat: must exceed 2"),
    ],
)
def test_what_it_cannot_take_is_one_line_naming_the_option(args, message):
    result = invoke("viability", *args)
    assert result.exit_code == 2, result.output
    assert message in result.output


def test_in_a_world_the_states_are_at_the_centre_line_with_height():
    payload = json_of("viability", "--world", "narrowing", "--heights", "3", "--states", "6", "--actions", "3")
    assert payload["world"] == "narrowing" and set(payload["state_axes"]) == {"y", "xdot", "ydot"}
    assert payload["state_axes"]["y"][0] == 0.0 and len(payload["state_axes"]["y"]) == 3
    assert payload["cells"] == 3 * 6 * 6 and isinstance(payload["kernel_heights"], list)
    for args, named in ((("--pitch-nodes", "3"), "--pitch-nodes"), (("--heights", "1"), "--heights")):
        result = invoke("viability", "--world", "narrowing", *args)
        assert result.exit_code == 2 and named in result.stderr, result.output
