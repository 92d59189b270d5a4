"""Paper Fig. 8: stability and basin of attraction against leg retraction (symmetric controls).

Sweeps zeta0 with psi0 fixed, following the period-1 gait by continuation; plots max |λ| and
the climb per jump with the zeta0 of jumping in place marked, the basin area on one fixed
window, and the basins themselves at three energy levels.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from experiments.report import Claim, new_figure
from sim_core.basin import DEFAULT_JUMPS, BasinGrid, compute_basin
from sim_core.basin_grid import DEFAULT_BASIN_WINDOW
from sim_core.chunks import ChunkMap, Progress, in_process
from sim_core.controls import ControlSchedule, LegControl
from sim_core.params import PhysicalParams
from sim_core.sweep import EnergySweep, energy_sweep, zeta0_values

TITLE = "Fig. 8 — stability and basin vs leg retraction"


@dataclass(frozen=True)
class Config:
    psi0_deg: float = 30.0
    zeta0_range: tuple[float, float] = (0.80, 0.97)
    steps: int = 35
    basin_grid: int = 60
    basin_jumps: int = DEFAULT_JUMPS
    shown_basins: tuple[float, ...] = (0.82, 0.88, 0.94)  # zeta0 of the basins drawn in full
    shown_grid: int = 120
    guess: tuple[float, float] = (-0.94, 0.6)  # near the gait at the first zeta0

    @classmethod
    def quick(cls) -> Config:
        """A coarse but real run, for smoke tests."""
        return cls(steps=6, basin_grid=16, shown_basins=(0.84, 0.94), shown_grid=24)


@dataclass(frozen=True)
class Result:
    config: Config
    sweep: EnergySweep
    window: BasinGrid
    shown: tuple  # (zeta0, Basin | None)


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
            basin = compute_basin(model, schedule, point.gait, grid, max_jumps=config.basin_jumps, chunk_map=chunk_map)
        shown.append((point.zeta0, basin))
    return Result(config, sweep, window, tuple(shown))


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
    ax.plot(zeta0, sweep.basin_area, "o-", color="tab:purple", markersize=3)
    mark_in_place(ax)
    grid = result.window
    ax.set(
        xlabel="zeta0 [l0]",
        ylabel="basin area [g l0]",
        title=f"Basin area ({grid.cells}² cells, {sweep.basin_jumps} jumps)",
    )

    for ax, (zeta0_shown, basin) in zip(axes[1], result.shown, strict=False):
        title = f"Basin at zeta0 = {zeta0_shown:.2f}"
        if basin is None:
            ax.set_title(f"{title}: no gait")
            continue
        jumps = np.where(basin.mask, basin.jumps_to_converge, np.nan)
        image = ax.imshow(
            jumps,
            origin="lower",
            extent=[*basin.grid.xdot_range, *basin.grid.ydot_range],
            aspect="auto",
            cmap="viridis_r",
        )
        ax.plot(*basin.gait.state, "r+", markersize=10, markeredgewidth=2, label="fixed point")
        ax.set(xlabel="xdot [sqrt(g l0)]", ylabel="ydot [sqrt(g l0)]", title=f"{title} (area {basin.area:.2f})")
        ax.grid(False)
        figure.colorbar(image, ax=ax, label="jumps to converge")
    for ax in axes[1, len(result.shown) :]:
        ax.set_visible(False)
    figure.suptitle(f"{TITLE}; psi0 = {result.config.psi0_deg:g}°, paper preset")
    return figure


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
    }


def data(result: Result) -> dict:
    return {
        "sweep": result.sweep.to_dict(),
        "shown_basins": [
            None if basin is None else {"zeta0": z, **basin.to_dict(include_grids=False)} for z, basin in result.shown
        ],
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
    return out


def notes(result: Result) -> list[str]:
    grid = result.window
    return [
        f"Basin areas on one window, xdot {grid.xdot_range[0]:g} … {grid.xdot_range[1]:g}, "
        f"ydot {grid.ydot_range[0]:g} … {grid.ydot_range[1]:g} [sqrt(g l0)], so they compare across zeta0; "
        "a cell counts when it comes within 0.02 of the fixed point.",
        "At the highest energies the basin reaches past the window, which caps those areas.",
    ]


def _spearman(x: np.ndarray, y: np.ndarray) -> float:
    from scipy.stats import spearmanr

    keep = np.isfinite(x) & np.isfinite(y)
    return float(spearmanr(x[keep], y[keep]).statistic) if keep.sum() > 2 else math.nan
