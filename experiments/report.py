"""What every figure study writes: the figure (PNG and SVG), its data (CSV and JSON with the
manifest of :mod:`experiments.manifest`), and its part of the markdown report.

A figure module (``experiments/fig*.py``) provides a frozen ``Config``, ``run(config, ...)``
returning a result, ``plot(result)`` returning a matplotlib figure, ``table(result)`` returning
the CSV columns, and ``claims(result)`` comparing the paper's statements with ours.
"""

from __future__ import annotations

import csv
import json
import math
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from experiments.manifest import json_safe

STYLE = {
    "font.size": 10,
    "axes.titlesize": 11,
    "axes.labelsize": 10,
    "legend.fontsize": 9,
    "axes.grid": True,
    "grid.alpha": 0.3,
    "figure.dpi": 110,
    "savefig.dpi": 150,
    "savefig.bbox": "tight",
    "svg.fonttype": "none",  # text stays text in the SVG
}


@dataclass(frozen=True)
class Claim:
    """One statement of the paper next to what we measured; ``agrees`` None if not decidable."""

    paper: str
    ours: str
    agrees: bool | None

    def to_dict(self) -> dict:
        return asdict(self)


def pyplot():
    """matplotlib's pyplot on the file-only Agg backend, imported on first use (it is slow)."""
    import matplotlib

    matplotlib.use("Agg")  # files only; no display on servers and CI
    import matplotlib.pyplot as plt

    return plt


def new_figure(rows: int, columns: int, size: tuple[float, float]):
    plt = pyplot()
    with plt.rc_context(STYLE):
        return plt.subplots(rows, columns, figsize=size, squeeze=False, layout="constrained")


def write_outputs(name: str, out: Path, *, figure, columns: dict[str, np.ndarray], document: dict) -> list[Path]:
    """Write ``name``.png/.svg/.csv/.json into ``out``; returns the paths written."""
    out.mkdir(parents=True, exist_ok=True)
    paths = [out / f"{name}.png", out / f"{name}.svg", out / f"{name}.csv", out / f"{name}.json"]
    plt = pyplot()
    with plt.rc_context(STYLE):
        figure.savefig(paths[0])
        figure.savefig(paths[1])
    plt.close(figure)
    _write_csv(paths[2], columns)
    paths[3].write_text(json.dumps(json_safe(document), indent=1, allow_nan=False) + "\n")
    return paths


def _write_csv(path: Path, columns: dict[str, np.ndarray]) -> None:
    length = max(len(values) for values in columns.values())
    with path.open("w", newline="") as handle:
        writer = csv.writer(handle)
        writer.writerow(columns)
        for row in range(length):
            writer.writerow([_csv_cell(values[row]) if row < len(values) else "" for values in columns.values()])


def _csv_cell(value) -> str:
    if isinstance(value, float | np.floating):
        return "" if not math.isfinite(value) else repr(float(value))
    return str(value)


def _cell(text: str) -> str:
    """Table-safe markdown: a bare ``|`` would end the cell."""
    return text.replace("|", "\\|")


def markdown_section(title: str, name: str, claims: list[Claim], notes: list[str]) -> str:
    """A report section: the figure, then a paper-vs-ours table, then notes."""
    mark = {True: "yes", False: "**no**", None: "n/a"}
    lines = [f"## {title}", "", f"![{name}]({name}.png)", "", "| the paper | ours | agrees |", "|---|---|---|"]
    lines += [f"| {_cell(c.paper)} | {_cell(c.ours)} | {mark[c.agrees]} |" for c in claims]
    lines += ["", *[f"- {note}" for note in notes], "", f"Data: `{name}.csv`, `{name}.json`; vector: `{name}.svg`.", ""]
    return "\n".join(lines)
