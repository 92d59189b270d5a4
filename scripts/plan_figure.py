"""A plan drawn over its world (issue 42): the footholds, the planned climb's path and each jump's
target foot, for a named world or ``random:SEED``.
Usage: PYTHONPATH=. python scripts/plan_figure.py [--world random:2] [--goal 1.5] [--out FILE]
"""

from __future__ import annotations

import argparse
import itertools
import math
from pathlib import Path

from experiments.report import new_figure
from sim_core.model.presets import get_preset
from sim_core.planning.planner import plan_climb
from sim_core.world.named import named_world
from sim_core.world.random_world import random_world
from sim_core.world.trajectory import simulate_world_trajectory

START = (-1.0, 0.5)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--world", default="random:2")
    parser.add_argument("--goal", type=float, default=1.5, help="[m]")
    parser.add_argument("--out", type=Path, default=Path("docs/figures/plan_random2.png"))
    args = parser.parse_args()
    robot = get_preset("paper")
    model, l0 = robot.to_model(), robot.scales.length
    kind, _, seed = args.world.partition(":")
    world = random_world(int(seed)) if kind == "random" else named_world(args.world, model.d_hat)
    plan = plan_climb(model, world, args.goal / l0, START)
    path, _climb = simulate_world_trajectory(model, world, plan.schedule, START, len(plan.steps) - 1)
    figure, axes = new_figure(1, 1, (5.5, 9.0))
    ax = axes[0, 0]
    for side in (world.left, world.right):
        points = side.points * l0
        for (a, b), mu in zip(itertools.pairwise(points), side.mu, strict=True):
            grip = mu != 0.0
            ax.plot([a[0], b[0]], [a[1], b[1]], color="tab:blue" if grip else "#cccccc", linewidth=3 if grip else 1)
    ax.plot(path.x * l0, path.y * l0, color="tab:orange", linewidth=1, label="body")
    for step in plan.steps:
        ax.plot(step.target[0] * l0, step.target[1] * l0, "o", color="tab:red", markersize=5)
        ax.annotate(f"{step.jump}: {math.degrees(step.leg.psi0):.1f}°/{step.leg.zeta0:.2f}",
                    (step.target[0] * l0, step.target[1] * l0), fontsize=7,
                    xytext=(6 if step.side == 0 else -70, 0), textcoords="offset points")  # fmt: skip
    ax.axhline(args.goal, color="tab:green", linestyle="--", linewidth=1, label=f"goal {args.goal:g} m")
    ax.set(xlabel="x [m]", ylabel="height [m]", aspect="equal", ylim=(-0.05, max(args.goal, plan.highest * l0) + 0.1),
           title=f"plan up {world.name} to {args.goal:g} m: {len(plan.steps) - 1} jumps, "
           f"estimated chance {plan.chance:.0%}")  # fmt: skip
    ax.legend(loc="lower center", fontsize=8)
    args.out.parent.mkdir(parents=True, exist_ok=True)
    figure.savefig(args.out, dpi=100)
    print(f"wrote {args.out}: {len(plan.steps) - 1} jumps, chance {plan.chance:.3f}, planned in {plan.seconds:.2f} s"
          " (the first plan of a process includes compiling the kernels)")  # fmt: skip


if __name__ == "__main__":
    main()
