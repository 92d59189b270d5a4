"""``parkour atlas`` (cli/atlas.py): the JSON contract and the map file."""

from tests.cli.helpers import json_of


def test_atlas_json_contract(tmp_path):
    plot = tmp_path / "atlas.png"
    args = ["--psi0-range", "25", "35", "--zeta0-range", "0.88", "0.97", "--grid", "2", "3", "--plot", str(plot)]
    payload = json_of("atlas", *args)
    assert set(payload) == {
        "row_label",
        "column_label",
        "rows",
        "columns",
        "period",
        "climb_per_jump",
        "max_abs_eigenvalue",
        "count",
        "cells",
    }
    assert len(payload["period"]) == 2 and len(payload["period"][0]) == 3
    assert plot.read_bytes()[:4] == b"\x89PNG"
