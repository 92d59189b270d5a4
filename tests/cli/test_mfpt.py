"""``parkour mfpt`` (cli/mfpt.py): the JSON contract and the errors a user can fix."""

import pytest

from tests.cli.helpers import invoke, json_of

CHEAP = ("--controls", "30:0.96", "--grid", "8", "--pitch-spacing", "2", "--guess", "-0.93", "0.2")


@pytest.fixture(autouse=True)
def chain_cache(tmp_path, monkeypatch):
    """Each test's own chain cache: the contract is checked on chains built, not loaded from a home."""
    from sim_core.robustness import mfpt_cache

    root = tmp_path / "mfpt"
    monkeypatch.setattr(mfpt_cache, "cache_root", lambda: root)
    return root


def test_mfpt_json_contract():
    payload = json_of("mfpt", *CHEAP)
    assert {"mfpt_jumps", "lambda2", "discretisation_error", "cells", "seconds"} <= set(payload)
    assert payload["mfpt_jumps"] > 1 and 0 < payload["lambda2"] < 1
    assert payload["controls"] == {"psi0_deg": pytest.approx(30.0), "zeta0": 0.96}
    coarse, fine = payload["grids"]
    assert fine["velocity_nodes"] == 8 and coarse["velocity_nodes"] == 6
    assert payload["cells"] == fine["cells"]
    assert payload["cached"] == [False, False]


def test_mfpt_loads_cached_chains_unless_told_not_to(chain_cache):
    first = json_of("mfpt", *CHEAP)
    assert first["cached"] == [False, False] and len(list(chain_cache.glob("*.npz"))) == 2
    again = json_of("mfpt", *CHEAP)
    assert again["cached"] == [True, True] and again["mfpt_jumps"] == first["mfpt_jumps"]
    before = {entry: entry.stat().st_mtime_ns for entry in chain_cache.iterdir()}
    assert json_of("mfpt", *CHEAP, "--no-cache")["cached"] == [False, False]
    assert {entry: entry.stat().st_mtime_ns for entry in chain_cache.iterdir()} == before, "neither loaded nor stored"


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (("--controls", "30:0.87,30:0.9"), "--controls: the chain takes one symmetric PSI0:ZETA0 pair"),
        (("--grid", "2"), "--grid: must be an integer in [4, 400], got 2"),
        (("--pitch-spacing", "9"), "--pitch-spacing: must be in [0.05, 4], got 9"),
        (("--asymmetry-psi0", "0.5"), "--asymmetry-psi0: must be 0 for the MFPT chain"),
        (("--d-hat", "1.9"), "d_hat: the chain's mid-chute section needs d_hat > 2, got 1.9"),
    ],
)
def test_what_the_chain_cannot_take_is_one_line_naming_the_option(args, message):
    result = invoke("mfpt", *args)
    assert result.exit_code == 2, result.output
    assert message in result.output
