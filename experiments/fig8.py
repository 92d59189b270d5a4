"""Paper Fig. 8: stability and basin of attraction against leg retraction (symmetric controls).

Sweeps zeta0 with psi0 fixed, following the period-1 gait by continuation; plots max |λ| and
the climb per jump with the zeta0 of jumping in place marked, the basin area on one fixed
window, and the basins themselves at three energy levels on one colour scale. Basin cells run to
``basin_jumps``; those still undecided are continued up to ``basin_jump_limit`` (doubling the
cap each round, :mod:`sim_core.basins.cells`), and what stays undecided is drawn as such. A scan
over psi0 tests the paper's stable descending gaits (:mod:`experiments.descending`).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np

from experiments import descending
from experiments.report import Claim, new_figure
from sim_core.basins.basin import DEFAULT_JUMPS, BasinGrid, compute_basin
from sim_core.basins.cells import FALLING_SPEED
from sim_core.basins.grid import DEFAULT_BASIN_WINDOW
from sim_core.basins.sweep import EnergySweep, energy_sweep, zeta0_values
from sim_core.chunks import ChunkMap, Progress, in_process
from sim_core.model.controls import ControlSchedule, LegControl
from sim_core.model.failures import Failure
from sim_core.model.params import PhysicalParams

TITLE = "Fig. 8 — stability and basin vs leg retraction"
UNDECIDED_COLOUR = "0.55"
FAILURE_COLOURS = {"slip": "#f6d2a8", "collapse": "#d4c4e6", "no_liftoff": "#b9e0da", "no_flight": "#f4b6bc",
                   "invalid_state": "#222222"}  # fmt: skip


@dataclass(frozen=True)
class Config:
    psi0_deg: float = 30.0
    zeta0_range: tuple[float, float] = (0.80, 0.97)
    steps: int = 35
    basin_grid: int = 60
    basin_jumps: int = DEFAULT_JUMPS  # the first cap
    # the undecided cells go on to here: at zeta0 0.96 (max |λ| 0.995) the basin stops growing by 960
    basin_jump_limit: int = 1000
    shown_basins: tuple[float, ...] = (0.82, 0.88, 0.94)  # zeta0 of the basins drawn in full
    shown_grid: int = 120
    guess: tuple[float, float] = (-0.94, 0.6)  # near the gait at the first zeta0
    descending_psi0_range: tuple[float, float] = (25.0, 45.0)  # [deg]: the scan for descending gaits
    descending_psi0_steps: int = 21

    @classmethod
    def quick(cls) -> Config:
        """A coarse but real run, for smoke tests."""
        return cls(steps=6, basin_grid=16, basin_jump_limit=240, shown_basins=(0.84, 0.94), shown_grid=24,
                   descending_psi0_steps=5)  # fmt: skip

    @property
    def descending_psi0s(self) -> np.ndarray:
        return np.linspace(*self.descending_psi0_range, self.descending_psi0_steps)


@dataclass(frozen=True)
class Result:
    config: Config
    sweep: EnergySweep
    window: BasinGrid
    shown: tuple  # (zeta0, Basin | None)
    descending: tuple[descending.DescendingRow, ...]


def run(robot: PhysicalParams, config: Config, *, chunk_map: ChunkMap = in_process, progress: Progress | None = None):
    model = robot.to_model()
    psi0 = math.radians(config.psi0_deg)
    window = BasinGrid(*DEFAULT_BASIN_WINDOW, config.basin_grid)
    sweep = energy_sweep(
        model,
        psi0,
        zeta0_values(*config.zeta0_range, config.steps),
        guess=config.guess,
        basin_grid=window,
        basin_jumps=config.basin_jumps,
        basin_jump_limit=config.basin_jump_limit,
        chunk_map=chunk_map,
        progress=progress,
    )
    shown_sweep = energy_sweep(model, psi0, list(config.shown_basins), guess=config.guess)
    shown = []
    for point in shown_sweep.points:
        basin = None
        if point.gait is not None:
            schedule = ControlSchedule.of(LegControl(psi0, point.zeta0))
            grid = BasinGrid(*DEFAULT_BASIN_WINDOW, config.shown_grid)
            basin = compute_basin(
                model,
                schedule,
                point.gait,
                grid,
                max_jumps=config.basin_jumps,
                jump_limit=config.basin_jump_limit,
                chunk_map=chunk_map,
            )
        shown.append((point.zeta0, basin))
    rows = descending.descending_gaits(model, config.descending_psi0s, guess=config.guess)
    return Result(config, sweep, window, tuple(shown), rows)


def plot(result: Result):
    sweep = result.sweep
    figure, axes = new_figure(2, 3, (12.0, 7.0))
    zeta0 = sweep.zeta0
    crossings = sweep.in_place_zeta0

    def mark_in_place(ax):
        for z in crossings:
            ax.axvline(z, color="tab:green", linewidth=1.5, label=f"in place, zeta0 = {z:.4f}")

    ax = axes[0, 0]
    ax.plot(zeta0, sweep.max_abs_eigenvalue, "o-", color="tab:blue", markersize=3)
    ax.axhline(1.0, color="gray", linestyle="--", linewidth=1, label="stability limit |λ| = 1")
    mark_in_place(ax)
    ax.set(xlabel="leg length at touchdown zeta0 [l0]", ylabel="max |eigenvalue|", title="Local stability")
    ax.legend(loc="upper left")

    ax = axes[0, 1]
    ax.plot(zeta0, sweep.climb_per_jump, "o-", color="tab:orange", markersize=3)
    ax.axhline(0.0, color="gray", linewidth=1)
    mark_in_place(ax)
    ax.set(xlabel="zeta0 [l0]", ylabel="climb per jump [l0]", title="Climbing rate")

    ax = axes[0, 2]
    ax.plot(zeta0, sweep.basin_area, "o-", color="tab:purple", markersize=3, label="basin area")
    mark_in_place(ax)
    grid = result.window
    config = result.config
    ax.set(xlabel="zeta0 [l0]", ylabel="basin area [g l0]", title=f"Basin area ({grid.cells}² cells)")
    twin = ax.twinx()
    twin.plot(zeta0, sweep.basin_undecided / grid.cells**2, "s--", color=UNDECIDED_COLOUR, markersize=2.5)
    twin.set(ylabel="undecided share of the window (grey)", ylim=(0.0, 1.0))
    twin.grid(False)

    _draw_basins(figure, axes[1], result.shown, config.basin_jump_limit)
    figure.suptitle(
        f"{TITLE}; psi0 = {config.psi0_deg:g}°, paper preset\nbasins: every cell run {config.basin_jumps} jumps, "
        f"the undecided ones continued (cap doubled each round) up to {config.basin_jump_limit} jumps"
    )
    return figure


def _draw_basins(figure, axes, shown, limit: int) -> None:
    """The basins on one logarithmic colour scale of jumps to converge, one colour bar for all;
    failed cells in a colour per failure, cells undecided at the jump limit in grey."""
    from matplotlib.colors import ListedColormap, LogNorm
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    basins = [basin for _, basin in shown if basin is not None]
    longest = max([int(basin.jumps_to_converge.max()) for basin in basins] + [2])
    norm = LogNorm(vmin=1, vmax=longest)
    codes = sorted({int(code) for basin in basins for code in np.unique(basin.failure) if code})
    outcomes = ListedColormap([UNDECIDED_COLOUR, *(FAILURE_COLOURS[Failure(code).code] for code in codes)])
    image = None
    for ax, (zeta0_shown, basin) in zip(axes, shown, strict=False):
        title = f"Basin at zeta0 = {zeta0_shown:.2f}"
        if basin is None:
            ax.set_title(f"{title}: no gait")
            continue
        extent = [*basin.grid.xdot_range, *basin.grid.ydot_range]
        outcome = np.full(basin.failure.shape, np.nan)
        outcome[basin.undecided] = 0
        for index, code in enumerate(codes, start=1):
            outcome[basin.failure == code] = index
        show = {"origin": "lower", "extent": extent, "aspect": "auto", "interpolation": "nearest"}
        ax.imshow(outcome, cmap=outcomes, vmin=-0.5, vmax=len(codes) + 0.5, **show)
        jumps = np.where(basin.mask, np.maximum(basin.jumps_to_converge, 1), np.nan)
        image = ax.imshow(jumps, cmap="viridis_r", norm=norm, **show)
        ax.plot(*basin.gait.state, "r+", markersize=10, markeredgewidth=2)
        ax.set(xlabel="xdot [sqrt(g l0)]", ylabel="ydot [sqrt(g l0)]", title=f"{title} (area {basin.area:.2f})")
        ax.grid(False)
    for ax in axes[len(shown) :]:
        ax.set_visible(False)
    if image is None:
        return
    figure.colorbar(image, ax=list(axes[: len(shown)]), label="jumps to converge (all panels)", pad=0.01)
    handles = [
        Patch(color=UNDECIDED_COLOUR, label=f"undecided at the {limit}-jump limit or falling"),
        *(Patch(color=FAILURE_COLOURS[Failure(code).code], label=f"fails: {Failure(code).code}") for code in codes),
        Line2D([], [], color="r", marker="+", linestyle="none", markersize=10, markeredgewidth=2, label="fixed point"),
    ]
    figure.legend(handles=handles, loc="outside lower center", ncols=len(handles))


def table(result: Result) -> dict[str, np.ndarray]:
    sweep = result.sweep
    states = np.array([p.gait.state if p.gait is not None else (np.nan, np.nan) for p in sweep.points])
    return {
        "zeta0": sweep.zeta0,
        "energy_mgl0": np.array([p.energy for p in sweep.points]),
        "xdot": states[:, 0],
        "ydot": states[:, 1],
        "max_abs_eigenvalue": sweep.max_abs_eigenvalue,
        "climb_per_jump_l0": sweep.climb_per_jump,
        "basin_area_gl0": sweep.basin_area,
        "basin_undecided_cells": sweep.basin_undecided,
        **descending.table_columns(result.descending),
    }


def data(result: Result) -> dict:
    return {
        "sweep": result.sweep.to_dict(),
        "shown_basins": [
            None if basin is None else {"zeta0": z, **basin.to_dict(include_grids=False)} for z, basin in result.shown
        ],
        "descending": [asdict(row) | {"stable": row.stable} for row in result.descending],
    }


def claims(result: Result) -> list[Claim]:
    sweep = result.sweep
    found = [p for p in sweep.points if p.gait is not None]
    lam = np.array([p.gait.max_abs_eigenvalue for p in found])
    z = np.array([p.zeta0 for p in found])
    area = np.array([np.nan if p.basin_area is None else p.basin_area for p in found])
    out = []
    stable_part = lam < 1.0
    lam_trend = bool(np.all(np.diff(lam) > 0)) if lam.size > 1 else None
    out.append(
        Claim(
            "More retraction (smaller zeta0) gives smaller max |λ|",
            f"max |λ| {lam[0]:.3f} at zeta0 = {z[0]:.3f} rising to {lam[-1]:.3f} at {z[-1]:.3f}"
            + (", monotone" if lam_trend else ", not monotone"),
            lam_trend,
        )
    )
    if stable_part.any():
        last_stable = z[stable_part][-1]
        out.append(
            Claim(
                "Stable period-1 gaits over a range of retraction",
                f"stable (|λ| < 1) for zeta0 ≤ {last_stable:.3f} in the sweep",
                True,
            )
        )
    low, high = area[0], area[-1]
    out.append(
        Claim(
            "More retraction gives a larger basin of attraction",
            f"basin area {low:.2f} g l0 at zeta0 = {z[0]:.3f}, {high:.2f} at {z[-1]:.3f}; "
            f"Spearman ρ(zeta0, area) = {_spearman(z, area):+.2f}",
            bool(low > high),
        )
    )
    if sweep.in_place_zeta0:
        zc = sweep.in_place_zeta0[0]
        beyond = sweep.climb_per_jump[sweep.zeta0 > zc]
        out.append(
            Claim(
                "A critical zeta0 of jumping in place; beyond it the gait descends",
                f"in place at zeta0 = {zc:.4f}; climb < 0 for all {beyond.size} sweep points above it",
                bool(beyond.size and np.all(beyond < 0)),
            )
        )
    else:
        out.append(Claim("A critical zeta0 of jumping in place", "no sign change of the climb in the sweep", False))
    out.append(descending.descending_claim(result.descending))
    return out


def notes(result: Result) -> list[str]:
    grid, config = result.window, result.config
    out = [
        f"Basin areas on one window, xdot {grid.xdot_range[0]:g} … {grid.xdot_range[1]:g}, "
        f"ydot {grid.ydot_range[0]:g} … {grid.ydot_range[1]:g} [sqrt(g l0)], so they compare across zeta0; "
        "a cell counts when it comes within 0.02 of the fixed point.",
        "At the highest energies the basin reaches past the window, which caps those areas.",
        f"Every basin cell runs {config.basin_jumps} jumps; the cells still undecided (neither converged nor "
        f"failed) go on from where they stopped, the cap doubled each round, up to {config.basin_jump_limit} jumps.",
    ]
    for zeta0, basin in result.shown:
        if basin is None:
            continue
        first, last = basin.rounds()[0], basin.rounds()[-1]
        out.append(
            f"Basin at zeta0 = {zeta0:.2f} ({basin.grid.cells}² cells): {first['converged']:,} cells converged by "
            f"{first['cap']} jumps, {last['converged']:,} by {last['cap']}; {last['undecided']:,} stay undecided, "
            f"{np.count_nonzero(basin.falling):,} of them falling down the chute (stopped once past "
            f"{FALLING_SPEED:g} sqrt(g l0): the model has no floor, so no limit decides them)."
        )
    return out


def _spearman(x: np.ndarray, y: np.ndarray) -> float:
    from scipy.stats import spearmanr

    keep = np.isfinite(x) & np.isfinite(y)
    return float(spearmanr(x[keep], y[keep]).statistic) if keep.sum() > 2 else math.nan
