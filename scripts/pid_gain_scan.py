"""The PID's default gains (docs/analyses.md, "Closed-loop height"): the gain scan they come from,
and how the default holds the height under the default noise.

Scan: every (kp, ki, kd) of KP x KI x KD at psi0 30° and 35°, each a noise-free climb to 0.55 m
from the zeta0 = 0.9 gait (``parkour pid``'s loop: experiments.fig12.PidClimb, 80 jumps as the
command), ranked by the jump after which the error stays within 2% of the climb (then overshoot);
a climb that fails, or enters the band only in its last SETTLED_FOR jumps, has not settled. It
prints each psi0's five fastest, where the default gains rank, and the ki > 0 sets that settled
sooner than the same kp, kd with ki = 0.

Noise: the default gains and psi0 35°'s five fastest, ``--seeds`` noisy climbs each (seeds
0 … N-1, ``--jumps`` each, the default NoiseModel): how many fail, and the median steady error
(mean |error| over the last quarter of the run) of those that do not.

Usage: python scripts/pid_gain_scan.py [--seeds 40] [--jumps 100] [--json]
Takes about half a minute on a shared 2-core machine (most of it finding the gaits and compiling).
"""

from __future__ import annotations

import argparse
import dataclasses
import itertools
import json
from collections import Counter

import numpy as np

from experiments.fig12 import Config, PidClimb
from sim_core.control.height_controller import HeightController
from sim_core.model.noise import NoiseModel
from sim_core.model.presets import get_preset

KP = (0.01, 0.02, 0.03, 0.04, 0.05, 0.06, 0.07, 0.08)
KI = (0.0, 0.0025, 0.005, 0.01)
KD = (0.0, 0.01, 0.02, 0.05, 0.1, 0.2)
PSI0_DEG = (30.0, 35.0)
SCAN_JUMPS = 80  # parkour pid's default
SHOWN = 5
SETTLED_FOR = 10  # jumps a climb must stay in the band at the end of the scan's run to count as settled


def climb_summary(run, time_scale: float, length_scale: float) -> dict:
    """One climb's figures, in SI where they have units."""
    settled = run.settling_jump()
    if run.failure is not None or (settled is not None and settled > SCAN_JUMPS - SETTLED_FOR):
        settled = None
    return {
        "failed": None if run.failure is None else run.failure.code,
        "settled_jump": settled,
        "settled_s": None if settled is None else float(run.time[settled] * time_scale),
        "overshoot": run.overshoot(),
        "steady_error_mm": run.steady_error() * length_scale * 1e3,
    }


def scan(robot, psi0_deg: float) -> list[dict]:
    """Every gain set of the scan at ``psi0_deg``, fastest settling first."""
    scales = robot.scales
    loop = PidClimb.of(robot.to_model(), Config(psi0_deg=psi0_deg, jumps=SCAN_JUMPS), scales.length)
    rows = []
    for kp, ki, kd in itertools.product(KP, KI, KD):
        gains = dataclasses.replace(loop.controller, kp=kp, ki=ki, kd=kd)
        run = dataclasses.replace(loop, controller=gains).climb()
        rows.append({"kp": kp, "ki": ki, "kd": kd, **climb_summary(run, scales.time, scales.length)})
    unsettled = SCAN_JUMPS + 1
    return sorted(rows, key=lambda r: (r["failed"] is not None, r["settled_jump"] or unsettled, r["overshoot"]))


def integral_helped(rows: list[dict]) -> list[dict]:
    """The ki > 0 rows that settled sooner than the same kp, kd with ki = 0."""
    unsettled = SCAN_JUMPS + 1
    without = {(r["kp"], r["kd"]): r["settled_jump"] or unsettled for r in rows if r["ki"] == 0}
    return [r for r in rows if r["ki"] > 0 and (r["settled_jump"] or unsettled) < without[(r["kp"], r["kd"])]]


def noisy_runs(robot, gains: dict, seeds: int, jumps: int) -> dict:
    """``gains`` (kp, ki, kd) at psi0 35° under the default noise, seeds 0 … seeds-1."""
    scales = robot.scales
    loop = PidClimb.of(robot.to_model(), Config(psi0_deg=35.0, jumps=jumps), scales.length)
    loop = dataclasses.replace(loop, controller=dataclasses.replace(loop.controller, **gains))
    runs = [loop.climb(NoiseModel(), seed) for seed in range(seeds)]
    held = [run.steady_error() for run in runs if run.failure is None]
    return {
        **gains,
        "seeds": seeds,
        "jumps": jumps,
        "failed": sum(run.failure is not None for run in runs),
        "failure_codes": dict(Counter(run.failure.code for run in runs if run.failure is not None)),
        "median_steady_error_l0": float(np.median(held)) if held else None,
        "median_steady_error_cm": float(np.median(held)) * scales.length * 100 if held else None,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seeds", type=int, default=40, help="noisy climbs with the default gains")
    parser.add_argument("--jumps", type=int, default=100, help="jumps per noisy climb")
    parser.add_argument("--json", action="store_true", help="print the whole result as JSON")
    args = parser.parse_args()
    robot = get_preset("paper")
    default = HeightController
    report = {"scan": {}}
    for psi0_deg in PSI0_DEG:
        rows = scan(robot, psi0_deg)
        gains = [(r["kp"], r["ki"], r["kd"]) for r in rows]
        rank = gains.index((default.kp, default.ki, default.kd))
        report["scan"][f"{psi0_deg:g}"] = {"default_rank": rank + 1, "of": len(rows), "rows": rows,
                                           "ki_helped": integral_helped(rows)}  # fmt: skip
    candidates = [{"kp": default.kp, "ki": default.ki, "kd": default.kd}]
    candidates += [{key: r[key] for key in ("kp", "ki", "kd")} for r in report["scan"]["35"]["rows"][:SHOWN]]
    report["noise"] = [noisy_runs(robot, gains, args.seeds, args.jumps) for gains in candidates]
    if args.json:
        print(json.dumps(report, indent=2))
        return
    for psi0_deg, found in report["scan"].items():
        helped = len(found["ki_helped"])
        print(f"psi0 {psi0_deg}°: default (kp {default.kp}, ki {default.ki}, kd {default.kd}) ranks "
              f"{found['default_rank']} of {found['of']}; ki > 0 settled sooner in {helped}")  # fmt: skip
        for r in found["rows"][:SHOWN]:
            print(f"  kp {r['kp']:<5} ki {r['ki']:<6} kd {r['kd']:<5} settled jump {r['settled_jump']} "
                  f"({r['settled_s'] and round(r['settled_s'], 1)} s), overshoot {r['overshoot']:.1%}, "
                  f"steady error {r['steady_error_mm']:.2f} mm, failed {r['failed']}")  # fmt: skip
    print(f"noise (psi0 35°, {args.seeds} seeds x {args.jumps} jumps): the default, then the five fastest at 35°")
    for n in report["noise"]:
        error = "-" if n["median_steady_error_l0"] is None else (
            f"{n['median_steady_error_l0']:.3f} l0 ({n['median_steady_error_cm']:.2f} cm)")  # fmt: skip
        print(f"  kp {n['kp']:<5} ki {n['ki']:<6} kd {n['kd']:<5} {n['failed']} failed {n['failure_codes']}; "
              f"median steady error of the rest {error}")  # fmt: skip


if __name__ == "__main__":
    main()
