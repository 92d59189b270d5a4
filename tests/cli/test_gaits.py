"""``parkour fixed-point`` and ``parkour gaits`` (cli/gaits.py): the gait JSON contract."""

from tests.cli.helpers import invoke, json_of
from tests.sim_core.section.test_fixed_points import GAIT_KEYS  # one gait in fixed-point and gaits --json


def test_fixed_point_json_contract():
    payload = json_of("fixed-point", "--controls", "30:0.87,30:0.9", "--period", "2", "--guess", "-0.8", "-0.15")
    assert list(payload) == GAIT_KEYS, "orbit and motion joined the original seven keys, at the end"
    assert payload["period"] == 2 and payload["stable"] is True
    assert len(payload["orbit"]) == 2 and payload["orbit"][0] == payload["state"] and payload["motion"] == "climbing"
    assert len(payload["eigenvalues"]) == 2 and all(len(pair) == 2 for pair in payload["eigenvalues"])
    assert payload["residual"] < 1e-9


def test_fixed_point_without_guess_searches():
    assert json_of("fixed-point")["stable"] is True


def test_fixed_point_without_any_gait_says_so_in_one_line():
    result = invoke("fixed-point", "--controls", "80:0.99")
    assert result.exit_code == 2
    assert result.stderr == "error: no period-1 gait found for controls 80°:0.99; give a starting state explicitly\n"


def test_gaits_lists_motion():
    gaits = json_of("gaits", "--controls", "30:0.98", "--grid", "3")["gaits"]
    assert gaits and all(gait["motion"] in {"climbing", "in place", "descending"} for gait in gaits)
    assert all(list(gait) == GAIT_KEYS for gait in gaits)
