"""What every figure study writes (experiments/report.py): the figure as PNG and SVG, its columns as
CSV (ragged columns padded, NaN as an empty cell), its document as strict JSON, and a markdown
section with the paper-vs-ours table (pipes in cells escaped)."""

from __future__ import annotations

import csv
import json
import math

import numpy as np

from experiments.report import STYLE, Claim, markdown_section, new_figure, pyplot, write_outputs

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


def test_figures_are_drawn_off_screen_on_a_grid_of_axes():
    assert pyplot().get_backend().lower() == "agg", "files only: no display on servers and CI"
    figure, axes = new_figure(2, 3, (6.0, 4.0))
    assert axes.shape == (2, 3), "always a 2-D grid, even of one row"
    assert tuple(figure.get_size_inches()) == (6.0, 4.0)
    _, single = new_figure(1, 1, (2.0, 2.0))
    assert single.shape == (1, 1)
    pyplot().close("all")


def test_write_outputs_writes_the_figure_its_table_and_its_document(tmp_path):
    figure, axes = new_figure(1, 1, (3.0, 2.0))
    axes[0, 0].plot([0, 1], [0, 1])
    axes[0, 0].set_title("a title kept as text")
    columns = {"zeta0": np.array([0.8, 0.9, 1.0]), "area": np.array([1.5, np.nan]), "label": np.array(["a", "b", "c"])}
    document = {"figure": "figX", "value": math.nan, "array": np.array([1.0, np.inf]), "n": np.int64(3)}
    paths = write_outputs("figX", tmp_path / "out", figure=figure, columns=columns, document=document)

    assert [path.name for path in paths] == ["figX.png", "figX.svg", "figX.csv", "figX.json"]
    assert paths[0].read_bytes()[:8] == PNG_MAGIC
    assert "a title kept as text" in paths[1].read_text(), f"svg.fonttype {STYLE['svg.fonttype']}: text stays text"
    with paths[2].open(newline="") as handle:
        rows = list(csv.reader(handle))
    assert rows == [["zeta0", "area", "label"], ["0.8", "1.5", "a"], ["0.9", "", "b"], ["1.0", "", "c"]], (
        "NaN and a shorter column's missing rows are empty cells"
    )
    assert json.loads(paths[3].read_text()) == {"figure": "figX", "value": None, "array": [1.0, None], "n": 3}
    assert not pyplot().fignum_exists(figure.number), "the figure is closed once written"


def test_a_report_section_shows_the_figure_and_a_table_of_the_papers_claims():
    claims = [
        Claim("max |λ| < 1", "max |λ| = 0.8", True),
        Claim("the basin grows", "it shrinks", False),
        Claim("failures are pitch drift", "mixed", None),
    ]
    section = markdown_section("Fig. 8 — stability", "fig8", claims, ["a note"])
    lines = section.splitlines()
    assert lines[0] == "## Fig. 8 — stability" and "![fig8](fig8.png)" in lines
    assert "| max \\|λ\\| < 1 | max \\|λ\\| = 0.8 | yes |" in lines, "a pipe inside a cell would end it"
    assert "| the basin grows | it shrinks | **no** |" in lines
    assert "| failures are pitch drift | mixed | n/a |" in lines
    assert "- a note" in lines and "Data: `fig8.csv`, `fig8.json`; vector: `fig8.svg`." in lines
    assert all(line.count("|") - line.count("\\|") == 4 for line in lines if line.startswith("| ")), "3 columns"


def test_a_claim_is_plain_json():
    claim = Claim("the paper", "ours", None)
    assert json.loads(json.dumps(claim.to_dict())) == {"paper": "the paper", "ours": "ours", "agrees": None}
