"""Calibration against robots of known truth whose runs fall: fitted against true, in standard errors.

For each hidden truth and seed, four noisy tracked climbs (the gaits of
``tests.tracked_climbs.VARIED_LEGS``, the default noise of docs/model.md §5.1, 1 mm tracker noise)
of up to ``--jumps`` jumps are fitted; a climb that ended before its jumps fell, and its series
says so. Printed per fit: each parameter's error in percent (``alpha``) or its unit, and in
standard errors; the estimated control noise; what was cut and what was an outlier. The figures
of docs/calibration.md ("Measured with falls") come from this script.

Usage: PYTHONPATH=. python scripts/calibration_truths.py [--seeds 0-5] [--jumps 60] [--truth NAME ...]
       [--all-seeds] [--json]
"""

from __future__ import annotations

import argparse
import json
import math

import numpy as np

from sim_core.calibration.calibrate import calibrate
from sim_core.calibration.fit import PARAMETERS, CalibrationFit, vector_of
from sim_core.calibration.touchdown_series import TouchdownSeries, pitch_at
from sim_core.model.noise import NoiseModel
from sim_core.model.walls import Wall
from tests.tracked_climbs import PAPER, VARIED_LEGS, TrackedClimb, Truth, tracked_climb

TRUTHS = {
    # issue 24's finding: a lightly damped robot whose fourth gait falls within a few dozen jumps
    "finding": Truth.of(alpha=84.0, c_zeta=0.6, c_psi=0.2, psi0_offset_deg=(-1.0, 0.5), zeta0_offset=(-0.006, 0.002)),
    # docs/calibration.md's first robot
    "damped": Truth.of(alpha=72.0, c_zeta=1.25, c_psi=0.8, psi0_offset_deg=(0.6, -0.8), zeta0_offset=(0.004, -0.005)),
    "soft": Truth.of(alpha=62.0, c_zeta=0.9, c_psi=0.45, psi0_offset_deg=(0.8, 1.2), zeta0_offset=(0.005, 0.003)),
    "stiff": Truth.of(alpha=100.0, c_zeta=0.45, c_psi=0.35, psi0_offset_deg=(-0.4, -1.1), zeta0_offset=(-0.002, 0.0)),
}
UNITS = {"alpha": "%", "c_zeta": "", "c_psi": "", "psi0_offset_deg.left": "deg", "psi0_offset_deg.right": "deg",
         "zeta0_offset.left": "l0", "zeta0_offset.right": "l0"}  # fmt: skip


def series_of(climb: TrackedClimb, *, fell: bool) -> TouchdownSeries:
    """A tracked climb as calibration reads a stored run of it."""
    return TouchdownSeries.of(
        state=[td.state for td in climb.touchdowns],
        foot_height=[td.foot_height / PAPER.leg_length for td in climb.touchdowns],
        commanded=[(math.radians(p), z) for p, z in climb.controls],
        right_leg=[td.wall == Wall.RIGHT for td in climb.touchdowns],
        pitch=pitch_at([td.time for td in climb.touchdowns], climb.frames["time"], climb.frames["pitch"]),
        fell=fell,
    )


def fell(climb: TrackedClimb, jumps: int) -> bool:
    """Whether a climb of ``jumps`` jumps fell: it ended early (a finished one detects ``jumps - 1``
    touchdowns or more: the first, from the floor, has no flight before it)."""
    return len(climb.touchdowns) < jumps - 1


def runs(truth: Truth, seed: int, *, jumps: int, noise: NoiseModel | None = None) -> list[TouchdownSeries]:
    """Four tracked climbs of ``truth`` (the gaits of VARIED_LEGS), seeded."""
    rng = np.random.default_rng(seed)
    climbs = [tracked_climb(truth, legs, jumps=jumps, noise=noise or NoiseModel(), rng=rng) for legs in VARIED_LEGS]
    return [series_of(climb, fell=fell(climb, jumps)) for climb in climbs]


def errors(fit: CalibrationFit, truth: Truth) -> dict:
    """Per parameter: ``value``, ``truth``, ``stderr``, ``error`` (percent for alpha) and ``sigmas``."""
    found, true = vector_of(fit.model, fit.offsets), vector_of(truth.robot.to_model(), truth.offsets)
    rows = {}
    for name, value, exact in zip(PARAMETERS, found, true, strict=True):
        error = value - exact
        rows[name] = {"value": float(value), "truth": float(exact), "stderr": fit.stderr[name],
                      "error": 100 * error / exact if name == "alpha" else float(error),
                      "sigmas": float(error / fit.stderr[name])}  # fmt: skip
    return rows


def measure(name: str, seed: int, jumps: int, *, without_falls: bool = False) -> dict | None:
    """One fit of truth ``name``; None where no climb fell and ``without_falls`` is not set."""
    truth = TRUTHS[name]
    series = runs(truth, seed, jumps=jumps)
    if not without_falls and not any(s.fell for s in series):
        return None
    fit = calibrate(series, PAPER.to_model())
    return {
        "truth": name, "seed": seed, "falls": [len(s.state) for s in series if s.fell],
        "touchdowns": [len(s.state) for s in series], "pairs": fit.touchdowns_used, "params": errors(fit, truth),
        "noise": fit.noise, "outliers": [o.to_dict() for o in fit.outliers],
        "cut_at_fall": [list(c) for c in fit.cut_at_fall],
    }  # fmt: skip


def line(row: dict) -> str:
    worst = max(row["params"].items(), key=lambda item: abs(item[1]["sigmas"]))
    noise, outliers = row["noise"], [(o["series"], o["touchdown"]) for o in row["outliers"]]
    errors = " ".join(f"{n} {p['error']:+.3g}{UNITS[n]} ({p['sigmas']:+.1f})" for n, p in row["params"].items())
    return (
        f"{row['truth']:8s} seed {row['seed']:2d} touchdowns {row['touchdowns']} falls {row['falls']} "
        f"pairs {row['pairs']}\n    {errors}\n    worst {worst[0]} {worst[1]['sigmas']:+.1f} sigma; noise psi0 "
        f"{noise['psi0_deg']:.3f} deg, zeta0 {noise['zeta0']:.4f}; outliers {outliers}"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", default="0-5", help="first-last seed, inclusive")
    parser.add_argument("--jumps", type=int, default=60)
    parser.add_argument("--truth", action="append", choices=sorted(TRUTHS), help="default: all")
    parser.add_argument("--all-seeds", action="store_true", help="also fit seeds where no climb fell")
    parser.add_argument("--json", action="store_true")
    options = parser.parse_args()
    first, last = (int(v) for v in options.seeds.split("-"))
    rows = []
    for name in options.truth or TRUTHS:
        for seed in range(first, last + 1):
            row = measure(name, seed, options.jumps, without_falls=options.all_seeds)
            if row is None:
                continue
            rows.append(row)
            if not options.json:
                print(line(row), flush=True)
    if options.json:
        print(json.dumps(rows, indent=1))


if __name__ == "__main__":
    main()
