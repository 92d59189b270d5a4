"""The viability map's speed: the issue's 60² x 20² state x action grid on the paper model, the
compiled engine (sim_core.viability.engine with sim_core.viability.step_map's step map) side by side with
the same steps done the way a Python tool does them (scipy's solve_ivp per pair, through
sim_core.model.reference), on a random sample of the grid's pairs timed and scaled to the whole grid.

It prints: compile time (once per source change; numba caches it), the map's and the fixed
point's seconds, pairs per second, the baseline's seconds per pair and the ratio, and how many
sampled pairs land in the same bin both ways (the kernels are the same computation, so they
should all agree but for landings within integration error of a node).

Usage: python scripts/bench_viability.py [--states 60] [--actions 20] [--sample 1500] [--json]
"""

from __future__ import annotations

import argparse
import json
import math
import time

import numpy as np

from sim_core.model.controls import LegControl
from sim_core.model.failures import OK
from sim_core.model.presets import get_preset
from sim_core.model.reference import reference_jump
from sim_core.viability.engine import compute_viability
from sim_core.viability.grid import section_grid
from sim_core.viability.step_map import section_step_map


def scipy_step(model, state, action) -> tuple[np.ndarray, bool]:
    """One mid-chute step with scipy: fly to the wall (closed form), the jump by
    :func:`sim_core.model.reference.reference_jump` with the same leg next, back to the middle."""
    xdot, ydot = state
    psi0, zeta0 = action
    leg = LegControl(psi0, zeta0)
    to_wall = (0.5 * model.d_hat - zeta0 * math.cos(psi0)) / xdot
    status, next_xdot, next_ydot, _ = reference_jump(model, (-xdot, ydot - to_wall), leg, leg)
    if status != OK:
        return np.array([math.nan, math.nan]), True
    middle_xdot = -next_xdot
    return np.array([middle_xdot, next_ydot + to_wall * xdot / middle_xdot]), False


def run(states: int, actions: int, sample: int, seed: int) -> dict:
    model = get_preset("paper").to_model()
    step_map = section_step_map(model)
    began = time.perf_counter()
    compute_viability(step_map, section_grid(states=4, actions=2))
    compile_seconds = time.perf_counter() - began
    grid = section_grid(states=states, actions=actions)
    result = compute_viability(step_map, grid)
    rng = np.random.default_rng(seed)
    picks = rng.choice(grid.pairs, size=min(sample, grid.pairs), replace=False)
    action_count = grid.actions().shape[0]
    state_nodes, action_nodes = grid.states(), grid.actions()
    began = time.perf_counter()
    same = 0
    for pick in picks:
        state, action = state_nodes[pick // action_count], action_nodes[pick % action_count]
        reached, failed = scipy_step(model, state, action)
        index = np.unravel_index(pick, grid.shape)
        if failed:
            same += bool(result.failed[index])
        else:
            bins = [int(np.digitize(value, axis)) for value, axis in zip(reached, grid.state_axes, strict=True)]
            same += (not result.failed[index]) and bins == result.bins[index].tolist()
    scipy_per_pair = (time.perf_counter() - began) / len(picks)
    seconds = result.seconds_map + result.seconds_kernel
    return {
        "grid": {"states": list(grid.state_shape), "actions": list(grid.action_shape), "pairs": grid.pairs},
        "compile_seconds": compile_seconds,
        "map_seconds": result.seconds_map,
        "kernel_seconds": result.seconds_kernel,
        "seconds": seconds,
        "pairs_per_second": grid.pairs / result.seconds_map,
        "kernel_fraction": result.kernel_fraction,
        "sweeps": result.sweeps,
        "scipy_seconds_per_pair": scipy_per_pair,
        "scipy_seconds_whole_grid": scipy_per_pair * grid.pairs,
        "ratio": scipy_per_pair * grid.pairs / result.seconds_map,
        "sample": len(picks),
        "sample_same_bin": same / len(picks),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--states", type=int, default=60, help="nodes per velocity axis")
    parser.add_argument("--actions", type=int, default=20, help="nodes per control axis")
    parser.add_argument("--sample", type=int, default=1500, help="pairs the scipy baseline runs")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--json", action="store_true")
    options = parser.parse_args()
    report = run(options.states, options.actions, options.sample, options.seed)
    if options.json:
        print(json.dumps(report, indent=1))
        return
    grid = report["grid"]
    print(f"grid {grid['states']} states x {grid['actions']} actions = {grid['pairs']:,} pairs")
    print(f"compile (once per source change) {report['compile_seconds']:.1f} s")
    print(
        f"compiled: map {report['map_seconds']:.2f} s + fixed point {report['kernel_seconds']:.2f} s "
        f"({report['pairs_per_second']:,.0f} pairs/s; {report['sweeps']} sweeps; "
        f"kernel {report['kernel_fraction']:.1%})"
    )
    print(
        f"scipy per pair {report['scipy_seconds_per_pair'] * 1e3:.2f} ms -> whole grid "
        f"{report['scipy_seconds_whole_grid']:.0f} s; ratio {report['ratio']:.0f}x"
    )
    print(f"same outcome and bin on {report['sample']} sampled pairs: {report['sample_same_bin']:.2%}")


if __name__ == "__main__":
    main()
