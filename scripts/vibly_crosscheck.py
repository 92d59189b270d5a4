"""Cross-check of the viability engine (sim_core.viability.engine) against sheim/vibly, the reference
implementation of viability kernels (Heim & Spröwitz), on vibly's SLIP hopper.

Both compute the same grid side by side: vibly its own way (``compute_Q_map`` over a process pool,
as ``demos/computeQ_slip.py`` does, then ``compute_QV`` and ``project_Q2S(..., np.mean)``), and
ParkourLab's engine with sim_core.viability.slip_hopper's compiled copy of vibly's model (compiled once
first, its compile time reported apart). The engine runs with ``edges_extend=True``, vibly's
convention at the grid's edges: a state reached past the last node is judged by the edge node,
one below the first node counts as failed.

It prints and writes (``--out``/vibly_crosscheck.json): the fraction of state-action pairs with the
same failure flag, the same bin and the same viability (``Q_V``); the fraction of states with the
same kernel membership (``S_V``) and the spread of the measure's difference (``S_M``); the largest
difference of the state reached; the speed, two ways side by side; and a figure
(``--out``/vibly_crosscheck.png): both ``Q_V`` over state x action and where they differ.

The speed, two ways:

* wall clock: each side's whole run on every core (vibly's process pool, the engine's numba
  threads), its ratio. The machine's load skews it; the load average at start and end is printed.
* CPU time per pair on one core: vibly's ``p_map`` (with ``sa2xp``/``xp2s``) stepped pair by pair
  in this process over the grid (or ``--cpu-pairs`` of its pairs drawn at random), against the
  engine's transition map of the whole grid with numba held to one thread (best of 3), both by
  ``time.process_time``: the step maps alone, each on one core, which other work on the machine
  hardly changes.

vibly needs only numpy, scipy, matplotlib and numba (all in the project's environment); it is put
on ``sys.path`` from ``--vibly``, a checkout of github.com/sheim/vibly.

Usage: python scripts/vibly_crosscheck.py --vibly PATH --out DIR [--states 180] [--actions 161]
       [--cpu-pairs N] [--vibly-npz FILE]  (reuse vibly's results saved by an earlier run instead of
       recomputing; the wall-clock ratio then mixes two runs)

A checkout of vibly: ``git clone https://github.com/sheim/vibly /tmp/vibly`` (only its source is
read). Time on the shared 2-core machine, load average 3 to 7: the demo grid 8 minutes (vibly's
pool 4, its one-core pass 2.5), the 60 x 41 grid under a minute; the engine's compile comes on top
on an empty numba cache.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path

import numba
import numpy as np

from sim_core.viability.engine import ViabilityGrid, compute_viability, transition_map, viability_of_map
from sim_core.viability.slip_hopper import SlipHopper, slip_step, slip_step_map

DEMO_STATES = 180  # computeQ_slip.py: s_grid = np.linspace(0.1, 1, 181)[:-1]
DEMO_ACTIONS = 161  # computeQ_slip.py: a_grid = np.linspace(-10 / 180 * np.pi, 70 / 180 * np.pi, 161)
SHOWN_DISAGREEMENTS = 20
ENGINE_CPU_REPEATS = 3  # the engine's one-thread map is timed this often, the best kept


def demo_axes(states: int, actions: int) -> tuple[np.ndarray, np.ndarray]:
    """vibly's SLIP demo grid with ``states`` x ``actions`` nodes: normalised apex height [-] and
    angle of attack [rad]."""
    s_axis = np.linspace(0.1, 1, states + 1)[:-1]
    a_axis = np.linspace(-10 / 180 * np.pi, 70 / 180 * np.pi, actions)
    return s_axis, a_axis


def vibly_slip(vibly_path: Path):
    """vibly's package, its SLIP model and ``p_map`` set up as computeQ_slip.py sets them up."""
    sys.path.insert(0, str(vibly_path))
    import viability as vibly  # vibly's own package, found through --vibly
    from models import slip

    p = {"mass": 80.0, "stiffness": 8200.0, "resting_length": 1.0, "gravity": 9.81}
    p |= {"angle_of_attack": 1 / 5 * np.pi, "actuator_resting_length": 0}
    x0 = slip.reset_leg(np.array([0, 0.85, 5.5, 0, 0, 0, 0]), p)
    p["x0"] = x0
    p["total_energy"] = slip.compute_total_energy(x0, p)
    p_map = slip.p_map
    p_map.p, p_map.x, p_map.sa2xp, p_map.xp2s = p, x0, slip.sa2xp, slip.xp2s
    return vibly, slip, p_map, p


def run_vibly(vibly_path: Path, s_axis: np.ndarray, a_axis: np.ndarray) -> dict:
    """vibly's computeQ_slip.py on the grid, timed part by part."""
    vibly, slip, p_map, p = vibly_slip(vibly_path)
    grids = {"states": (s_axis,), "actions": (a_axis,)}
    began = time.perf_counter()
    p_map(*slip.sa2xp((0.5, 0.5), p))  # compiles vibly's numba functions before the pool forks
    warm_up = time.perf_counter() - began
    began = time.perf_counter()
    transitions = vibly.compute_Q_map(grids, p_map, parallel=True, keep_coords=True)
    seconds_q_map = time.perf_counter() - began
    began = time.perf_counter()
    q_v, s_v = vibly.compute_QV(transitions.q_map, grids)
    seconds_qv = time.perf_counter() - began
    began = time.perf_counter()
    s_m = vibly.project_Q2S(q_v, grids, proj_opt=np.mean)
    seconds_project = time.perf_counter() - began
    return {
        "Q_map": transitions.q_map,
        "Q_F": transitions.q_fail,
        "Q_V": q_v,
        "S_V": s_v,
        "S_M": s_m,
        "s_reached": transitions.q_reached[0].reshape(transitions.q_map.shape),
        "total_energy": p["total_energy"],
        "seconds_warm_up": warm_up,
        "seconds_q_map": seconds_q_map,
        "seconds_qv": seconds_qv,
        "seconds_project": seconds_project,
    }


def run_engine(s_axis: np.ndarray, a_axis: np.ndarray, hopper: SlipHopper):
    """The engine on the grid (compiled first on a small one), and the states it reaches."""
    step_map = slip_step_map(hopper)
    began = time.perf_counter()
    compute_viability(step_map, ViabilityGrid((s_axis[::40],), (a_axis[::40],)), edges_extend=True)
    compile_seconds = time.perf_counter() - began
    grid = ViabilityGrid((s_axis,), (a_axis,))
    result = compute_viability(step_map, grid, edges_extend=True)
    states, actions = grid.states(), grid.actions()
    pairs = np.repeat(states, len(actions), axis=0), np.tile(actions, (len(states), 1))
    reached = slip_step(*pairs, hopper)[0][:, 0].reshape(grid.shape)
    return result, reached, compile_seconds


def vibly_cpu_per_pair(vibly_path: Path, s_axis: np.ndarray, a_axis: np.ndarray, count: int) -> tuple[float, int]:
    """vibly's CPU seconds per pair on one core: ``p_map`` stepped pair by pair in this process, over
    every grid pair (``count`` 0) or ``count`` of them drawn at random (seed 0); and the pairs stepped."""
    _, slip, p_map, p = vibly_slip(vibly_path)
    pairs = [(s, a) for s in s_axis for a in a_axis]
    if 0 < count < len(pairs):
        pairs = [pairs[i] for i in np.random.default_rng(0).choice(len(pairs), count, replace=False)]
    p_map(*slip.sa2xp((0.5, 0.5), p))  # compiled before the clock starts
    began = time.process_time()
    for state_action in pairs:
        x, params = p_map.sa2xp(state_action, p)
        x_next, _ = p_map(x, params)
        p_map.xp2s(x_next, params)
    return (time.process_time() - began) / len(pairs), len(pairs)


def engine_cpu_per_pair(s_axis: np.ndarray, a_axis: np.ndarray, hopper: SlipHopper) -> float:
    """The engine's CPU seconds per pair on one core: its transition map of the grid with numba held
    to one thread, best of ENGINE_CPU_REPEATS (already compiled by :func:`run_engine`)."""
    grid, step_map = ViabilityGrid((s_axis,), (a_axis,)), slip_step_map(hopper)
    threads = numba.get_num_threads()
    numba.set_num_threads(1)
    try:
        times = []
        for _ in range(ENGINE_CPU_REPEATS):
            began = time.process_time()
            transition_map(step_map, grid)
            times.append(time.process_time() - began)
    finally:
        numba.set_num_threads(threads)
    return min(times) / grid.pairs


def compare(ref: dict, result, reached: np.ndarray, s_axis: np.ndarray, a_axis: np.ndarray) -> dict:
    """The agreement figures (module docstring)."""
    bin_shape = tuple(n + 1 for n in result.grid.state_shape)
    per_dimension = tuple(np.moveaxis(np.maximum(result.bins, 0), -1, 0))
    ours = np.where(result.failed, 0, np.ravel_multi_index(per_dimension, bin_shape))  # vibly's Q_map coding
    same_bin = (result.failed & ref["Q_F"]) | (~result.failed & ~ref["Q_F"] & (ours == ref["Q_map"]))
    both_land = ~result.failed & ~ref["Q_F"]
    strict = viability_of_map(result.grid, result.failed, result.bins, edges_extend=False)
    measure_difference = np.abs(result.measure - ref["S_M"])
    differing = np.argwhere(~same_bin | (result.viable_pairs != ref["Q_V"]))
    return {
        "pairs": int(result.failed.size),
        "same_failed": float(np.mean(result.failed == ref["Q_F"])),
        "same_bin": float(np.mean(same_bin)),
        "same_viable_pairs": float(np.mean(result.viable_pairs == ref["Q_V"])),
        "states": int(result.kernel.size),
        "same_kernel": float(np.mean(result.kernel == ref["S_V"])),
        "kernel_fraction": {"vibly": float(np.mean(ref["S_V"])), "parkourlab": result.kernel_fraction},
        "failed_fraction": {"vibly": float(np.mean(ref["Q_F"])), "parkourlab": float(np.mean(result.failed))},
        "measure_abs_difference": {
            "max": float(measure_difference.max()),
            "mean": float(measure_difference.mean()),
            "states_differing": int(np.count_nonzero(measure_difference > 0)),
        },
        "reached_abs_difference_max": float(np.max(np.abs(reached - ref["s_reached"])[both_land], initial=0.0)),
        "same_kernel_without_edges_extend": float(np.mean(strict.kernel == ref["S_V"])),
        "disagreements": [
            {
                "s": float(s_axis[i]),
                "aoa_deg": float(np.degrees(a_axis[j])),
                "vibly": _pair(ref["Q_F"], ref["Q_map"], ref["Q_V"], ref["s_reached"], i, j),
                "parkourlab": _pair(result.failed, ours, result.viable_pairs, reached, i, j),
            }
            for i, j in differing[:SHOWN_DISAGREEMENTS]
        ],
        "disagreeing_pairs": len(differing),
    }


def _pair(failed, bins, viable, reached, i, j) -> dict:
    return {
        "failed": bool(failed[i, j]),
        "bin": int(bins[i, j]),
        "viable": bool(viable[i, j]),
        "s_next": float(reached[i, j]),
    }


def plot(ref: dict, result, s_axis: np.ndarray, a_axis: np.ndarray, path: Path) -> None:
    """Both Q_V over state x action (failed pairs shaded apart) and where they differ."""
    import matplotlib  # only the script plots

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.colors import ListedColormap

    extent = (s_axis[0], s_axis[-1], np.degrees(a_axis[0]), np.degrees(a_axis[-1]))
    levels = ListedColormap(["#d9d9d9", "#8c96c6", "#238b45"])  # failed, not viable, viable
    figure, axes = plt.subplots(1, 3, figsize=(15, 4.6), sharey=True, constrained_layout=True)
    for axis, title, failed, viable in (
        (axes[0], "vibly Q_V", ref["Q_F"], ref["Q_V"]),
        (axes[1], "ParkourLab Q_V", result.failed, result.viable_pairs),
    ):
        image = np.where(failed, 0, np.where(viable, 2, 1))
        axis.imshow(image.T, origin="lower", aspect="auto", extent=extent, cmap=levels, vmin=0, vmax=2)
        axis.set_title(f"{title} (grey: fails, blue: not viable, green: viable)", fontsize=9)
        axis.set_xlabel("normalised apex height s")
    axes[0].set_ylabel("angle of attack [deg]")
    differ = np.zeros(result.failed.shape, dtype=int)
    differ[result.failed != ref["Q_F"]] = 1
    differ[result.viable_pairs != ref["Q_V"]] = 2
    axes[2].imshow(
        differ.T,
        origin="lower",
        aspect="auto",
        extent=extent,
        vmin=0,
        vmax=2,
        cmap=ListedColormap(["white", "orange", "red"]),
    )
    count = int(np.count_nonzero(differ))
    axes[2].set_title(f"disagreement: {count} of {differ.size} pairs (orange: failure, red: Q_V)", fontsize=9)
    axes[2].set_xlabel("normalised apex height s")
    figure.savefig(path, dpi=120)
    plt.close(figure)


def main(argv: list[str] | None = None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--vibly", type=Path, required=True, help="a checkout of github.com/sheim/vibly")
    parser.add_argument("--out", type=Path, required=True, help="folder for the JSON and the figure")
    parser.add_argument("--states", type=int, default=DEMO_STATES, help="apex-height nodes (demo: 180)")
    parser.add_argument("--actions", type=int, default=DEMO_ACTIONS, help="angle-of-attack nodes (demo: 161)")
    parser.add_argument("--vibly-npz", type=Path, help="vibly's results saved by an earlier run, not recomputed")
    parser.add_argument(
        "--cpu-pairs", type=int, default=0, help="pairs vibly steps on one core for its CPU time (0: every pair)"
    )
    args = parser.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    s_axis, a_axis = demo_axes(args.states, args.actions)
    load_at_start = os.getloadavg()
    if args.vibly_npz:
        ref = dict(np.load(args.vibly_npz))
        if ref["Q_map"].shape != (args.states, args.actions):
            parser.error(f"--vibly-npz holds a {ref['Q_map'].shape} grid, not ({args.states}, {args.actions})")
    else:
        ref = run_vibly(args.vibly.resolve(), s_axis, a_axis)
        np.savez(args.out / "vibly_reference.npz", s_axis=s_axis, a_axis=a_axis, **ref)
    hopper = SlipHopper(total_energy=float(ref["total_energy"]))
    result, reached, compile_seconds = run_engine(s_axis, a_axis, hopper)
    vibly_seconds = float(ref["seconds_q_map"] + ref["seconds_qv"] + ref["seconds_project"])
    engine_seconds = result.seconds_map + result.seconds_kernel
    engine_cpu = engine_cpu_per_pair(s_axis, a_axis, hopper)
    vibly_cpu, vibly_cpu_pairs = vibly_cpu_per_pair(args.vibly.resolve(), s_axis, a_axis, args.cpu_pairs)
    report = {
        "grid": {
            "states": args.states,
            "actions": args.actions,
            "s": [s_axis[0], s_axis[-1]],
            "aoa_deg": [float(np.degrees(a_axis[0])), float(np.degrees(a_axis[-1]))],
        },
        "agreement": compare(ref, result, reached, s_axis, a_axis),
        "seconds": {
            "vibly": {
                "q_map": float(ref["seconds_q_map"]),
                "compute_qv": float(ref["seconds_qv"]),
                "project": float(ref["seconds_project"]),
                "total": vibly_seconds,
                "numba_warm_up": float(ref["seconds_warm_up"]),
            },
            "parkourlab": {
                "map": result.seconds_map,
                "kernel": result.seconds_kernel,
                "total": engine_seconds,
                "compile": compile_seconds,
            },
            "speed_ratio": vibly_seconds / engine_seconds,
            "speed_ratio_with_compile": vibly_seconds / (engine_seconds + compile_seconds),
        },
        "cpu_per_pair_one_core": {
            "vibly": vibly_cpu,
            "vibly_pairs_stepped": vibly_cpu_pairs,
            "parkourlab": engine_cpu,
            "ratio": vibly_cpu / engine_cpu,
        },
        "machine": {
            "cpus": os.cpu_count(),
            "load_average_at_start": load_at_start,
            "load_average_at_end": os.getloadavg(),
            "vibly_reused_from": str(args.vibly_npz) if args.vibly_npz else None,
        },
    }
    plot(ref, result, s_axis, a_axis, args.out / "vibly_crosscheck.png")
    (args.out / "vibly_crosscheck.json").write_text(json.dumps(report, indent=2))
    agreement, seconds = report["agreement"], report["seconds"]
    print(f"grid {args.states} x {args.actions} = {agreement['pairs']} pairs")
    for key in ("same_failed", "same_bin", "same_viable_pairs", "same_kernel"):
        print(f"  {key:<20} {agreement[key]:.6f}")
    print(
        f"  |S_M difference|     max {agreement['measure_abs_difference']['max']:.3g}, "
        f"mean {agreement['measure_abs_difference']['mean']:.3g}"
    )
    print(f"  |s' difference| max  {agreement['reached_abs_difference_max']:.3g}")
    vibly_parts = seconds["vibly"]
    print(f"vibly {vibly_seconds:.2f} s (Q map {vibly_parts['q_map']:.2f}, compute_QV {vibly_parts['compute_qv']:.2f})")
    print(
        f"ParkourLab {engine_seconds:.3f} s (map {result.seconds_map:.3f}, kernel {result.seconds_kernel:.4f}); "
        f"compile {compile_seconds:.1f} s"
    )
    cpu, machine = report["cpu_per_pair_one_core"], report["machine"]
    print(
        f"speed, wall clock on {machine['cpus']} cores:  {seconds['speed_ratio']:.0f}x "
        f"({seconds['speed_ratio_with_compile']:.1f}x with compile)"
    )
    print(
        f"speed, CPU per pair on one core: {cpu['ratio']:.0f}x "
        f"(vibly {cpu['vibly'] * 1e3:.2f} ms over {cpu['vibly_pairs_stepped']} pairs, "
        f"ParkourLab {cpu['parkourlab'] * 1e6:.1f} us)"
    )
    load = " / ".join(f"{value:.2f}" for value in machine["load_average_at_start"])
    print(f"load average (1 / 5 / 15 min) {load} at start, {machine['load_average_at_end'][0]:.2f} at end")
    print(f"wrote {args.out / 'vibly_crosscheck.json'} and {args.out / 'vibly_crosscheck.png'}")
    return report


if __name__ == "__main__":
    main()
