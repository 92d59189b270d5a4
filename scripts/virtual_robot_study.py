"""Controllers on a robot unlike the paper's: calibrate from its open-loop runs, design on the
calibration, hold a height, beside the paper-model laws (issue 27's virtual-robot figure).

For each hidden truth (``scripts.calibration_truths.TRUTHS``: stiffness, damping and servo offsets
unlike the paper's), four open-loop tracked climbs (the gaits of ``tests.tracked_climbs.VARIED_LEGS``,
40 jumps, default noise) are calibrated (``sim_core.calibration.calibrate.calibrate``), and each controller
climbs ``--runs`` times to ``--target`` for ``--jumps`` touchdowns, closed as a live run closes it
(``tests.closed_climbs``: the PC's touchdown detector and the live law, without sockets or real
time), the default noise on every run, seeds 100, 101, ... The calibrated laws are designed on
the fitted model, detect touchdowns with it and take the fitted leg offsets off each command; the
paper laws know only the paper preset, as a service started without a calibration. The truth is
used to simulate the robot and nowhere else. A run *holds* the target when it does not fall and
its last 100 touchdowns are within 2 cm of it on average.

Usage: PYTHONPATH=. python scripts/virtual_robot_study.py [--truth NAME ...] [--runs 10] [--jumps 300]
       [--target 0.55] [--json]
"""

from __future__ import annotations

import argparse
import json

import numpy as np

from backend.robot.live_law import LiveLaw
from scripts.calibration_truths import TRUTHS, runs
from sim_core import LegControl, PhysicalParams
from sim_core.calibration.calibrate import calibrate
from sim_core.control.design import law_holding
from sim_core.model.controls import NO_OFFSETS
from sim_core.model.noise import NoiseModel
from tests.closed_climbs import closed_climb, held
from tests.tracked_climbs import PAPER

LEGS = (LegControl.from_degrees(35.0, 0.9), LegControl.from_degrees(35.0, 0.9))
CONTROLLERS = (("pid", "paper"), ("pid-pitch", "paper"), ("lqr", "paper"), ("lqr", "calibrated"),
               ("deadbeat", "calibrated"))  # fmt: skip


def calibrated_robot(truth_name: str, seed: int = 0):
    """The PC's robot and leg offsets from four open-loop runs of the truth (40 jumps each)."""
    fit = calibrate(runs(TRUTHS[truth_name], seed, jumps=40), PAPER.to_model())
    robot = PhysicalParams.from_model(fit.model, mass=PAPER.mass, leg_length=PAPER.leg_length, gravity=PAPER.gravity)
    return robot, fit.offsets


def study(truth_name: str, controllers=CONTROLLERS, *, runs_per: int, jumps: int, target_m: float) -> dict:
    """Per controller: runs that held, touchdowns done, mean |error| over each run's last 100 [m]."""
    truth = TRUTHS[truth_name]
    robots = {"paper": (PAPER, NO_OFFSETS), "calibrated": calibrated_robot(truth_name)}
    rows = []
    for name, design in controllers:
        robot, offsets = robots[design]
        outcomes = []
        for seed in range(100, 100 + runs_per):
            law = law_holding(name, robot.to_model(), target_m / robot.leg_length, LEGS[0].psi0_deg)
            live = LiveLaw(target_m, law, robot.leg_length, LEGS[1], offsets)
            climb = closed_climb(truth, robot, LEGS, live, touchdowns=jumps, noise=NoiseModel(),
                                 rng=np.random.default_rng(seed))  # fmt: skip
            last = np.array([td.body_height for td in climb.touchdowns[-100:]])
            error = float(np.mean(np.abs(last - target_m))) if last.size else None
            outcomes.append({"held": held(climb, target_m), "touchdowns": len(climb.touchdowns), "fell": climb.fell,
                             "mean_abs_error_m": error})  # fmt: skip
        errors = [o["mean_abs_error_m"] for o in outcomes if o["held"]]
        rows.append({"controller": name, "designed_on": design, "held": sum(o["held"] for o in outcomes),
                     "fell": sum(o["fell"] for o in outcomes), "runs": runs_per, "outcomes": outcomes,
                     "mean_abs_error_m_when_held": float(np.mean(errors)) if errors else None})  # fmt: skip
    return {"truth": truth_name, "target_m": target_m, "jumps": jumps, "controllers": rows}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--truth", nargs="*", default=list(TRUTHS), choices=list(TRUTHS))
    parser.add_argument("--runs", type=int, default=10)
    parser.add_argument("--jumps", type=int, default=300)
    parser.add_argument("--target", type=float, default=0.55)
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args()
    results = [study(name, runs_per=args.runs, jumps=args.jumps, target_m=args.target) for name in args.truth]
    if args.json:
        print(json.dumps(results, indent=1))
        return
    for result in results:
        print(f"truth {result['truth']}: {result['jumps']} touchdowns to {result['target_m']} m")
        for row in result["controllers"]:
            error = row["mean_abs_error_m_when_held"]
            shown = "—" if error is None else f"{100 * error:.2f} cm"
            print(f"  {row['controller']:>9} ({row['designed_on']:>10}): held {row['held']}/{row['runs']}, "
                  f"fell {row['fell']}, mean |error| when held {shown}")  # fmt: skip


if __name__ == "__main__":
    main()
