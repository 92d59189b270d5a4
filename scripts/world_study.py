"""Reach maps and MJTF in worlds (issue 41): the narrowing chute and two random-foothold worlds.

For each world: the world drawn (footholds by grip), the reach map of the symmetric schedules
over psi0 x zeta0 (the highest foot reached, in metres, from touchdown 0 at the floor with the
paper gait's velocity) and its failure map by ending; then MJTF in each world under the default
noise of docs/model.md §5.1 at three energy levels, printed as a markdown table with the 95% CI
(and on parallel walls, for comparison). Writes docs/figures/world_reach.png (or --out).
Usage: PYTHONPATH=. python scripts/world_study.py [--out FILE] [--jumps 40] [--trials 200] [--cap 300]
"""

from __future__ import annotations

import argparse
import itertools
import math
from pathlib import Path

import numpy as np

from experiments.report import new_figure, pyplot
from sim_core.model.noise import NoiseModel
from sim_core.model.presets import get_preset
from sim_core.robustness.mjtf import mjtf_study
from sim_core.world.named import named_world
from sim_core.world.random_world import random_world
from sim_core.world.reach import CAPPED, TOP, reach_map
from sim_core.world.world import World

START = (-1.0, 0.5)  # touchdown 0's velocity [sqrt(g l0)]: near the paper's period-1 gait
PSI0_DEG = np.linspace(15.0, 50.0, 36)
ZETA0 = np.linspace(0.80, 0.97, 18)
ENDINGS = (TOP, CAPPED, "slip", "no_flight", "floor", "no_touchdown", "collapse", "no_liftoff", "invalid_state")
COLOURS = ("#2ca02c", "#98df8a", "#f6d2a8", "#f4b6bc", "#8c8c8c", "#9467bd", "#d4c4e6", "#b9e0da", "#000000")
MJTF_LEVELS = (0.86, 0.9, 0.94)


def worlds(d_hat: float) -> list[World]:
    return [named_world("narrowing", d_hat), random_world(1), random_world(2)]


def draw_world(ax, world: World, l0: float) -> None:
    for side in (world.left, world.right):
        points = side.points * l0
        for (a, b), mu in zip(itertools.pairwise(points), side.mu, strict=True):
            grip = mu != 0.0
            ax.plot([a[0], b[0]], [a[1], b[1]], color="tab:blue" if grip else "#cccccc", linewidth=2.5 if grip else 1)
    ax.set(xlabel="x [m]", ylabel="height [m]", title=f"{world.name}: footholds (blue), no grip (grey)", aspect="equal")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path("docs/figures/world_reach.png"))
    parser.add_argument("--jumps", type=int, default=40)
    parser.add_argument("--trials", type=int, default=200)
    parser.add_argument("--cap", type=int, default=300)
    args = parser.parse_args()
    robot = get_preset("paper")
    model, l0 = robot.to_model(), robot.scales.length
    chosen = worlds(model.d_hat)
    figure, axes = new_figure(len(chosen), 3, (15.0, 5.2 * len(chosen)))
    for row, world in enumerate(chosen):
        reach = reach_map(model, world, PSI0_DEG, ZETA0, START, args.jumps)
        draw_world(axes[row, 0], world, l0)
        extent = (PSI0_DEG[0], PSI0_DEG[-1], ZETA0[0], ZETA0[-1])
        image = axes[row, 1].imshow(reach.highest * l0, origin="lower", aspect="auto", extent=extent, cmap="viridis")
        figure.colorbar(image, ax=axes[row, 1], label="highest foot [m]")
        axes[row, 1].set(
            xlabel="psi0 [deg]", ylabel="zeta0 [l0]", title=f"reach in {args.jumps} jumps (top {world.top * l0:.2f} m)"
        )
        codes = np.vectorize(ENDINGS.index)(reach.endings())
        plt = pyplot()
        colours = plt.matplotlib.colors.ListedColormap(COLOURS)
        axes[row, 2].imshow(codes, origin="lower", aspect="auto", extent=extent, cmap=colours, vmin=-0.5,
                            vmax=len(ENDINGS) - 0.5, interpolation="nearest")  # fmt: skip
        handles = [plt.matplotlib.patches.Patch(color=COLOURS[i], label=f"{ending} ({count})")
                   for i, ending in enumerate(ENDINGS) if (count := reach.outcomes()[ending])]  # fmt: skip
        axes[row, 2].legend(handles=handles, loc="upper right", fontsize=8)
        axes[row, 2].set(xlabel="psi0 [deg]", ylabel="zeta0 [l0]", title="how each schedule ends")
        print(f"{world.name}: {reach.outcomes()}; highest {reach.highest.max() * l0:.2f} m")
    args.out.parent.mkdir(parents=True, exist_ok=True)
    figure.savefig(args.out, dpi=90)
    print(f"wrote {args.out}")
    print("\n| world | zeta0 | MJTF | 95% CI | capped | failures |\n|---|---|---|---|---|---|")
    for world in (None, *chosen):
        study = mjtf_study(model, math.radians(30.0), MJTF_LEVELS, noise=NoiseModel(), trials=args.trials,
                           cap=args.cap, seed=41, world=world)  # fmt: skip
        for level in study.levels:
            outcomes = level.histogram()
            capped = outcomes.pop(CAPPED)
            failures = ", ".join(f"{code} {count}" for code, count in outcomes.items() if count)
            low, high = level.ci95
            name = "parallel walls (the map)" if world is None else world.name
            print(f"| {name} | {level.zeta0:.2f} | {level.mean:.1f} | {low:.1f}–{high:.1f} | "
                  f"{capped}/{level.jumps.size} | {failures} |")  # fmt: skip


if __name__ == "__main__":
    main()
