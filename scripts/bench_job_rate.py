"""How many jumps a second the job worker computes here: what the job work budget is sized by.

Runs MJTF trials (the paper's 30°/0.9 gait, default noise, cap 1000) as a job chunk does, after
one warm-up chunk, and prints the rate and the jumps an hour of it amounts to
(``backend.schemas.WORK_BUDGET_JUMPS`` is that, rounded). ``--json`` for the numbers alone.
"""

from __future__ import annotations

import argparse
import json
import math
import time

from backend.schemas import WORK_BUDGET_JUMPS
from sim_core import get_preset
from sim_core.model.noise import NoiseModel, trial_seeds
from sim_core.robustness.mjtf import level_starts
from sim_core.robustness.mjtf_trials import run_trials


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--trials", type=int, default=512)
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args()
    model = get_preset("paper").to_model()
    level = level_starts(model, math.radians(30.0), [0.9], guess=(-0.93, -0.2))[0]
    seeds = trial_seeds(0, 0, args.trials)
    run_trials(model, level.schedule, level.start, NoiseModel(), seeds[:8], 1000)  # compiled or loaded
    started = time.perf_counter()
    jumps, _ = run_trials(model, level.schedule, level.start, NoiseModel(), seeds, 1000)
    rate = float(jumps.sum()) / (time.perf_counter() - started)
    result = {"jumps_per_s": rate, "jumps_per_hour": rate * 3600.0, "budget_jumps": WORK_BUDGET_JUMPS}
    if args.json:
        print(json.dumps(result))
        return
    print(f"{rate:,.0f} jumps/s; an hour is {rate * 3600:,.0f} jumps; the job budget is {WORK_BUDGET_JUMPS:,} jumps")


if __name__ == "__main__":
    main()
