"""Reproducing the paper (experiments/reproduce.py): every figure writes its files and the report,
and the paper's claims hold. The command over it is tested in tests/cli/test_reproduce.py; each
figure's study beside it (tests/experiments/test_fig7.py ...)."""

import json

import pytest

from experiments.reproduce import FIGURES, figure_module, figure_names, reproduce
from sim_core import ParameterError, get_preset


def test_figure_names():
    assert figure_names(["all"]) == list(FIGURES)
    assert all(hasattr(figure_module(name), "claims") for name in FIGURES)
    assert figure_names(["fig8", "fig8", "fig7"]) == ["fig8", "fig7"]
    with pytest.raises(ParameterError, match=r"^figure: must be one of"):
        figure_names(["fig9"])
    with pytest.raises(ParameterError, match=r"^figure:"):
        figure_names([])


def test_quick_reproduction_writes_every_file(tmp_path):
    written = reproduce(["all"], tmp_path, get_preset("paper"), quick=True)
    for name in FIGURES:
        for suffix in (".png", ".svg", ".csv", ".json"):
            path = tmp_path / f"{name}{suffix}"
            assert path in written and path.stat().st_size > 500, path
        document = json.loads((tmp_path / f"{name}.json").read_text())
        assert {"figure", "config", "model", "code_version", "created", "data", "claims"} <= set(document)
        assert document["model"]["alpha"] == pytest.approx(77.623, abs=1e-3)
        assert (tmp_path / f"{name}.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    report = (tmp_path / "report.md").read_text()
    assert report.count("\n## Fig.") == 4 and "quick (coarse)" in report
    assert "| max |λ|" not in report, "pipes inside table cells are escaped"


@pytest.mark.slow
def test_full_reproduction_agrees_with_the_paper(tmp_path):
    """The full configurations (about 6 minutes, Fig. 8's basins continued to 1000 jumps nearly all
    of it): every decidable claim of Figs. 7, 8, 11, 12 holds."""
    reproduce(["all"], tmp_path, get_preset("paper"))
    for name in FIGURES:
        claims = json.loads((tmp_path / f"{name}.json").read_text())["claims"]
        failed = [claim for claim in claims if claim["agrees"] is False]
        assert not failed, (name, failed)
