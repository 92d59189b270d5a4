"""A controller's MFPT by splitting (sim_core.robustness.splitting) side by side with Monte-Carlo trials of the
same loop (sim_core.control.study, the same law, climb, noise and start): values, 95% intervals,
seconds each.

Cases are CONTROLLER:VELOCITY[:TRIALS] (the per-jump velocity noise, the other sigmas default, no
pitch drift; TRIALS overrides --trials for that case: the deadbeat's law costs 0.1 ms a jump).
By default: where Monte-Carlo can tell (velocity 0.05 and 0.03), and where it cannot
(0.02 and the default 0.01, where the controllers that score 0 failures in 400 jumps are ranked
by splitting alone: --mc-max-velocity 0.025 skips the Monte-Carlo there).

Monte-Carlo's estimate: when every trial fails, their mean jumps to failure (its interval from
their spread); when some survive the trial length, the exponential MLE (jumps lived over
failures; its interval from the failures' Poisson count), as in a metastable loop past its climb.

Usage: python scripts/bench_loop_mfpt.py [--cases pid:0.05,lqr:0.05] [--trials 1000]
                                         [--jumps 30000] [--mc-max-velocity 0.025] [--json]
"""

from __future__ import annotations

import argparse
import json
import math
import time

from scipy.stats import chi2

from experiments.control_study import Config, laws_for
from sim_core.control.study import control_study
from sim_core.model.noise import NoiseModel
from sim_core.model.presets import get_preset
from sim_core.robustness.splitting import loop_mfpt

CASES = ",".join(f"{name}:{velocity}" for velocity in (0.05, 0.03, 0.02, 0.01) for name in ("pid", "lqr", "deadbeat"))


def monte_carlo(outcome) -> tuple[float, tuple[float, float]]:
    """The loop's mean jumps to failure and its 95% interval, from trials that may be censored."""
    if outcome.failures == outcome.trials:
        mean, half = outcome.jumps_to_failure()
        return mean, (mean - half, mean + half)
    lived = float(outcome.failure_jumps.sum()) + (outcome.trials - outcome.failures) * outcome.jumps
    failures = outcome.failures
    if failures == 0:
        return math.inf, (lived / chi2.ppf(0.975, 2) * 2, math.inf)
    low = 2 * lived / chi2.ppf(0.975, 2 * failures)
    high = 2 * lived / chi2.ppf(0.025, 2 * failures)
    return lived / failures, (low, high)


def case(model, leg_length: float, name: str, velocity: float, trials: int, jumps: int, with_mc: bool) -> dict:
    noise = NoiseModel(velocity=velocity, pitch_drift_deg=0.0)
    config = Config(controllers=(name,), noise=noise)
    loop, (law,) = laws_for(model, config, leg_length)
    began = time.perf_counter()
    split = loop_mfpt(model, law, loop.start, config.start_zeta0, noise)
    row = {
        "controller": name,
        "velocity": velocity,
        "mfpt_jumps": split.mfpt_jumps,
        "mfpt_ci95": list(split.ci95),
        "mfpt_seconds": time.perf_counter() - began,
        "rate": split.rate,
        "runs_extinct": sum(p == 0.0 for p in split.probabilities),
    }
    if with_mc:
        began = time.perf_counter()
        (outcome,) = control_study(model, [law], loop.start, config.start_zeta0, jumps, 0, trials, noise)
        mean, ci95 = monte_carlo(outcome)
        seconds = time.perf_counter() - began
        row |= {"mc_jumps": mean, "mc_ci95": list(ci95), "mc_failed": outcome.failures, "mc_trials": trials,
                "mc_trial_jumps": jumps, "mc_seconds": seconds, "ratio": split.mfpt_jumps / mean}  # fmt: skip
    return row


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", default=CASES)
    parser.add_argument("--trials", type=int, default=1000)
    parser.add_argument("--jumps", type=int, default=30_000)
    parser.add_argument("--mc-max-velocity", type=float, default=0.025)
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args()
    robot = get_preset("paper")
    rows = []
    for item in args.cases.split(","):
        name, velocity, *trials = item.split(":")
        velocity = float(velocity)
        trials = int(trials[0]) if trials else args.trials
        rows.append(case(robot.to_model(), robot.scales.length, name, velocity, trials, args.jumps,
                         velocity >= args.mc_max_velocity))  # fmt: skip
        if not args.json:
            print(_line(rows[-1]), flush=True)
    if args.json:
        print(json.dumps(rows, indent=1))
    return 0


def _line(row: dict) -> str:
    low, high = row["mfpt_ci95"]
    text = (f"{row['controller']:>9} v {row['velocity']:<5} splitting {row['mfpt_jumps']:.4g} [{low:.3g}, {high:.3g}] "
            f"{row['mfpt_seconds']:.1f} s ({row['runs_extinct']} runs extinct)")  # fmt: skip
    if "mc_jumps" in row:
        low, high = row["mc_ci95"]
        text += (f" | MC {row['mc_jumps']:.4g} [{low:.3g}, {high:.3g}] {row['mc_failed']}/{row['mc_trials']} failed in "
                 f"{row['mc_trial_jumps']} jumps, {row['mc_seconds']:.1f} s | ratio {row['ratio']:.3f}")  # fmt: skip
    return text


if __name__ == "__main__":
    raise SystemExit(main())
