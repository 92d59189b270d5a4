"""Foot placement following a plan under noise, on random-foothold worlds (issue 42, a first measure).

For each world seed: a plan to ``--goal`` metres (sim_core.planning.planner.plan_climb), then
``--trials`` noisy trials (default noise, trial i = seed i) of (a) the placement law following the
plan with replanning (sim_core.planning.follow.follow_plan) and (b) the plan's legs replayed
without feedback, on the same draws (sim_core.robustness.world_trials; counted there: every
planned jump done without a failure, the last foot near the goal). Also: the law's CPU time per jump on the plan's
touchdowns (time.thread_time, the compiled law alone) and the planning time.
Usage: PYTHONPATH=. python scripts/placement_study.py [--worlds 10] [--trials 20] [--goal 1.5]
"""

from __future__ import annotations

import argparse
from collections import Counter

import numpy as np

from sim_core.control.laws.placement import PlacementSettings
from sim_core.model.failures import Failure
from sim_core.model.noise import NoiseModel
from sim_core.model.presets import get_preset
from sim_core.planning.follow import follow_plan, law_us_per_jump
from sim_core.planning.planner import plan_climb
from sim_core.robustness.world_trials import run_world_trials
from sim_core.world.geometry import pack
from sim_core.world.random_world import random_world

START = (-1.0, 0.5)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--worlds", type=int, default=10)
    parser.add_argument("--trials", type=int, default=20)
    parser.add_argument("--goal", type=float, default=1.5, help="[m]")
    args = parser.parse_args()
    preset = get_preset("paper")
    model, metres = preset.to_model(), preset.scales.length
    goal, noise, settings = args.goal / metres, NoiseModel(), PlacementSettings()
    totals, law_us, plan_s = Counter(), [], []
    for seed in range(args.worlds):
        world = random_world(seed)
        sides = pack(world, model.mu)
        plan = plan_climb(model, world, goal, START)
        plan_s.append(plan.seconds)
        if not plan.reaches_goal:
            print(f"random:{seed}: no plan (highest {plan.highest * metres:.2f} m)")
            continue
        law_us.append(law_us_per_jump(model, sides, plan, settings.array()))
        outcomes = [follow_plan(model, world, plan, goal, noise, trial) for trial in range(args.trials)]
        seeds, cap = np.arange(args.trials, dtype=np.int64), len(plan.steps) - 1
        jumps, status = run_world_trials(model, plan.schedule.as_array(), START, noise, seeds, cap, world, 0.0)
        replayed = int(np.sum((status == 0) & (jumps == cap)))
        placed = sum(outcome.reached for outcome in outcomes)
        failures = Counter(Failure(o.status).code for o in outcomes if not o.reached and o.status)
        totals.update(placement=placed, replayed=replayed, trials=args.trials,
                      replans=sum(o.replans for o in outcomes))  # fmt: skip
        print(f"random:{seed}: {len(plan.steps) - 1} jumps, chance {plan.chance:.2f}, plan {plan.seconds:.2f} s; "
              f"placement {placed}/{args.trials} ({dict(failures)}), replayed {replayed}/{args.trials}, "
              f"law {law_us[-1]:.0f} us")  # fmt: skip
    trials = max(totals["trials"], 1)
    print(f"all: placement {totals['placement']}/{totals['trials']} ({totals['placement'] / trials:.0%}), "
          f"replayed {totals['replayed']}/{totals['trials']} ({totals['replayed'] / trials:.0%}), "
          f"replans per trial {totals['replans'] / trials:.2f}; plan median {np.median(plan_s):.2f} s, "
          f"max {max(plan_s):.2f} s; law median {np.median(law_us):.0f} us, max {max(law_us):.0f} us")  # fmt: skip


if __name__ == "__main__":
    main()
