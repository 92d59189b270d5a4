"""Can random-foothold worlds be climbed to 1.5 m by *some* sequence of jumps? (issue 41)

`random_world`'s defaults were chosen from geometry (docs/worlds.md). This checks them: for each
seed, a beam search over jump-by-jump controls — from every touchdown, each of a set of leg
controls for the next leg (psi0 15–45° by 5°, zeta0 0.80 (``--zeta0-low``)–0.96 by 0.02: 63), one jump each in the
compiled kernel, keeping the ``--beam`` highest distinct touchdowns — until a foot stands at or
above ``--goal`` metres. Noise-free; the velocity at touchdown 0 from ``--state``. A world it
climbs is climbable; one it does not may still be (the search is a beam, not exhaustive).
Usage: PYTHONPATH=. python scripts/world_climbability.py [--seeds 20] [--goal 1.5] [--beam 200]
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np

from sim_core.model.controls import ControlSchedule, LegControl
from sim_core.model.failures import OK
from sim_core.model.presets import get_preset
from sim_core.world.climb import climb_world, first_touchdown
from sim_core.world.geometry import pack
from sim_core.world.random_world import random_world
from sim_core.world.stride import world_orbit_batch


def controls(zeta0_low: float = 0.80) -> np.ndarray:
    """The legs the search tries: psi0 15–45° by 5°, zeta0 from ``zeta0_low`` to 0.96 by 0.02, (K, 2)."""
    return np.array([(math.radians(p), z) for p in range(15, 50, 5) for z in np.arange(zeta0_low, 0.961, 0.02)])


CONTROLS = controls()


def climb_height(model, world, state, goal: float, beam: int, jumps: int) -> tuple[float, tuple[int, ...]]:
    """The highest foot [l0] the search reaches (stopping at ``goal``) and the legs that reach it
    (indices into :data:`CONTROLS`, touchdown 0's first)."""
    sides = pack(world, model.mu)
    nodes = []  # (touchdown row, side, segment, leg index, the legs so far)
    for leg in range(len(CONTROLS)):
        schedule = ControlSchedule.of(LegControl(*CONTROLS[leg]))
        row, segment = first_touchdown(model, world, schedule, state, 0.0)
        nodes.append((row, 0, segment, leg, (leg,)))
    best, path = 0.0, ()
    for _ in range(jumps):
        count = len(nodes) * len(CONTROLS)
        states = np.zeros((count, 2, 4))
        on_side = np.zeros((count, 2), dtype=np.int64)
        on_segment = np.zeros((count, 2), dtype=np.int64)
        schedules = np.empty((count, 2, 2))
        for i, (row, side, segment, leg, _legs) in enumerate(nodes):
            block = slice(i * len(CONTROLS), (i + 1) * len(CONTROLS))
            states[block, 0], on_side[block, 0], on_segment[block, 0] = row, side, segment
            schedules[block, 0], schedules[block, 1] = CONTROLS[leg], CONTROLS
        status, completed = np.empty(count, dtype=np.int64), np.empty(count, dtype=np.int64)
        world_orbit_batch(schedules, 0, model.record(), sides, states, on_side, on_segment, status, completed)
        ok = np.flatnonzero((status == OK) & (states[:, 1, 1] >= 0.0))  # not below the floor
        if ok.size == 0:
            return best, path
        legs = ok % len(CONTROLS)
        feet = states[ok, 1, 1] - CONTROLS[legs, 1] * np.sin(CONTROLS[legs, 0])
        if feet.max() > best:
            top = int(feet.argmax())
            best, path = float(feet[top]), (*nodes[ok[top] // len(CONTROLS)][4], int(legs[top]))
        if best >= goal:
            return best, path
        # the beam: the highest feet, one per (height cell, side, velocity cell)
        order = np.argsort(-feet)
        nodes_before, seen, nodes = nodes, set(), []
        for j in order:
            i = ok[j]
            key = (round(feet[j], 2), int(on_side[i, 1]), round(states[i, 1, 2], 1), round(states[i, 1, 3], 1))
            if key in seen:
                continue
            seen.add(key)
            parent = nodes_before[i // len(CONTROLS)]
            nodes.append((states[i, 1].copy(), int(on_side[i, 1]), int(on_segment[i, 1]), int(legs[j]),
                          (*parent[4], int(legs[j]))))  # fmt: skip
            if len(nodes) >= beam:
                break
    return best, path


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=20)
    parser.add_argument("--goal", type=float, default=1.5, help="[m]")
    parser.add_argument("--beam", type=int, default=200)
    parser.add_argument("--jumps", type=int, default=60)
    parser.add_argument("--state", type=float, nargs=2, default=(-1.0, 0.5))
    parser.add_argument("--zeta0-low", type=float, default=0.80, help="the least zeta0 tried (most energy)")
    args = parser.parse_args()
    global CONTROLS
    CONTROLS = controls(args.zeta0_low)
    robot = get_preset("paper")
    model, l0 = robot.to_model(), robot.scales.length
    goal = args.goal / l0
    climbed = 0
    for seed in range(args.seeds):
        started = time.perf_counter()
        world = random_world(seed)
        height, legs = climb_height(model, world, tuple(args.state), goal, args.beam, args.jumps)
        # replayed as one climb by the validated entry point: the search's bookkeeping checked
        schedule = ControlSchedule.of(*(LegControl(*CONTROLS[leg]) for leg in legs))
        replay = climb_world(model, world, schedule, tuple(args.state), len(legs) - 1)
        last = replay.states[-1, 1] - schedule[len(legs) - 1].zeta0 * math.sin(schedule[len(legs) - 1].psi0)
        assert replay.failure is None and abs(last - height) < 1e-9, (seed, replay.failure, last, height)
        reached = height >= goal
        climbed += reached
        shown = ", ".join(f"{math.degrees(CONTROLS[leg, 0]):.0f}:{CONTROLS[leg, 1]:.2f}" for leg in legs)
        print(f"seed {seed:3d}: highest foot {height * l0:.2f} m in {len(legs) - 1} jumps"
              f"{' — climbed' if reached else ''}, legs {shown} ({time.perf_counter() - started:.1f} s)")  # fmt: skip
    print(f"{climbed} of {args.seeds} default random worlds climbed to {args.goal:g} m by the search")


if __name__ == "__main__":
    main()
