"""The gait atlas drawn as a map: where climbing, in-place and descending gaits live."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from experiments.report import STYLE, new_figure, pyplot
from sim_core.section.atlas import GaitAtlas


def plot_atlas(atlas: GaitAtlas, title: str):
    """Climb per jump of each cell's most stable gait (red climbs, blue descends; blank: none)
    with the in-place contour, and the gaits' periods."""
    from matplotlib.colors import TwoSlopeNorm

    figure, axes = new_figure(1, 2, (12.0, 4.8))
    extent = [*_edges(atlas.columns), *_edges(atlas.rows)]  # cells centred on their values
    climb = atlas.climb_per_jump
    finite = climb[np.isfinite(climb)]
    span = max(float(np.max(np.abs(finite))), 1e-6) if finite.size else 1.0

    ax = axes[0, 0]
    image = ax.imshow(
        climb,
        origin="lower",
        extent=extent,
        aspect="auto",
        cmap="RdBu_r",
        norm=TwoSlopeNorm(vcenter=0.0, vmin=-span, vmax=span),
        interpolation="nearest",
    )
    if finite.size and finite.min() < 0 < finite.max():
        columns, rows = np.meshgrid(atlas.columns, atlas.rows)
        ax.contour(columns, rows, np.nan_to_num(climb, nan=np.nan), levels=[0.0], colors="k", linewidths=1.5)
    figure.colorbar(image, ax=ax, label="climb per jump [l0] (most stable gait)")
    ax.set(xlabel=atlas.column_label, ylabel=atlas.row_label, title="Where stable gaits climb (blank: none found)")
    ax.grid(False)

    ax = axes[0, 1]
    period = atlas.period.astype(float)
    period[period == 0] = np.nan
    values = sorted({int(p) for p in np.unique(period[np.isfinite(period)])})
    image = ax.imshow(period, origin="lower", extent=extent, aspect="auto", cmap="viridis", interpolation="nearest")
    if values:
        figure.colorbar(image, ax=ax, ticks=values, label="period [jumps]")
    multiple = np.argwhere(atlas.count > 1)
    if multiple.size:
        ax.plot(atlas.columns[multiple[:, 1]], atlas.rows[multiple[:, 0]], "w.", markersize=4, label="several gaits")
        ax.legend(loc="upper right", fontsize=8)
    ax.set(xlabel=atlas.column_label, ylabel=atlas.row_label, title="Period of the most stable gait")
    ax.grid(False)
    figure.suptitle(title)
    return figure


def _edges(values: np.ndarray) -> tuple[float, float]:
    half = 0.5 * (values[1] - values[0]) if values.size > 1 else 0.5
    return float(values[0] - half), float(values[-1] + half)


def save_atlas(atlas: GaitAtlas, path: Path, title: str) -> Path:
    """Write the map to ``path`` (.png or .svg)."""
    plt = pyplot()
    figure = plot_atlas(atlas, title)
    with plt.rc_context(STYLE):
        figure.savefig(path)
    plt.close(figure)
    return path
