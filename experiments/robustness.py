"""The calibrated model's Mean Jumps To Failure beside the robot's own (docs/calibration.md).

Per gait the robot was run at, the robot's jumps to failure come from its runs: a run that ended
in a fall failed after its jumps; one stopped first (its jumps done, a person's stop) is censored —
it would have gone on. The model's come from MJTF trials (:func:`sim_core.robustness.mjtf_trials.run_trials`) of the
calibrated model, its legs' offsets applied to the commanded gait, with the noise the calibration
estimated from the same runs; trials reaching ``cap`` are censored alike.

Both are summarised with one estimator, so they compare: jumps to failure as geometric (a
constant chance to fail per jump), the MJTF estimate is ``jumps / failures`` — all jumps, capped
and censored ones included, over the failures seen — with the exact 95 % interval of a Poisson
count of failures over that exposure (chi-square quantiles). No failure gives a lower bound only.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from sim_core.model.controls import ControlSchedule, LegControl, LegOffsets
from sim_core.model.noise import NoiseModel, trial_seeds
from sim_core.model.params import ModelParams

CONFIDENCE = 0.95


@dataclass(frozen=True)
class JumpsToFailure:
    """Jumps of several tries and whether each ended in a failure; the MJTF estimate and its interval."""

    jumps: tuple[int, ...]
    failed: tuple[bool, ...]

    @property
    def failures(self) -> int:
        return sum(self.failed)

    @property
    def exposure(self) -> int:
        return int(sum(self.jumps))

    def estimate(self) -> dict:
        """``{"tries", "failures", "jumps", "mjtf", "ci95"}``; ``mjtf`` None (and ``ci95[1]`` None)
        without a failure, ``ci95[0]`` then the lower bound."""
        from scipy.stats import chi2

        failures, exposure = self.failures, self.exposure
        alpha = 1.0 - CONFIDENCE
        # Exposure over the Poisson interval of the failure count (Garwood): MJTF = 1 / rate.
        upper = 2.0 * exposure / chi2.ppf(alpha / 2, 2 * failures) if failures else None
        lower = 2.0 * exposure / chi2.ppf(1.0 - alpha / 2, 2 * failures + 2)
        return {
            "tries": len(self.jumps),
            "failures": failures,
            "jumps": exposure,
            "mjtf": exposure / failures if failures else None,
            "ci95": [lower, upper],
        }


def noise_of(estimate: dict, pitch_drift_deg: float, offsets: LegOffsets) -> NoiseModel:
    """The MJTF noise from a calibration's estimate (``CalibrationFit.noise``): the controls' noise as
    estimated, the state's the input's less what the tracker adds (both are in ``state_input``),
    the pitch drift as tracked, and the right leg's offset relative to the left's."""
    process = math.sqrt(max(estimate["state_input"] ** 2 - estimate["state_output"] ** 2, 0.0))
    return NoiseModel(
        psi0_deg=estimate["psi0_deg"],
        zeta0=estimate["zeta0"],
        velocity=process,
        pitch_drift_deg=pitch_drift_deg,
        asymmetry_psi0_deg=offsets.psi0_offset_deg[1] - offsets.psi0_offset_deg[0],
        asymmetry_zeta0=offsets.zeta0_offset[1] - offsets.zeta0_offset[0],
    )


def simulated(
    model: ModelParams, offsets: LegOffsets, legs, noise: NoiseModel, *, trials: int, cap: int, seed: int, stream: int
) -> JumpsToFailure:
    """MJTF trials of the gait commanded ``legs`` ((psi0_deg, zeta0) left, right): both legs carry
    the left leg's offset in the schedule, the right leg the difference as the noise's asymmetry."""
    from sim_core import gait_of
    from sim_core.model.presets import START_GUESS
    from sim_core.robustness.mjtf_trials import run_trials

    left = LegOffsets(psi0_offset_deg=(offsets.psi0_offset_deg[0],) * 2, zeta0_offset=(offsets.zeta0_offset[0],) * 2)
    commanded = [LegControl.from_degrees(*pair) for pair in legs]
    schedule = ControlSchedule.of(*(left.applied(leg, right_leg=False) for leg in commanded))
    start = gait_of(model, schedule, guess=START_GUESS).state
    jumps, status = run_trials(model, schedule.as_array(), start, noise, trial_seeds(seed, stream, trials), cap)
    return JumpsToFailure(tuple(int(j) for j in jumps), tuple(bool(s != 0) for s in status))


def compare(
    robot_runs: dict[tuple, JumpsToFailure],
    model: ModelParams,
    offsets: LegOffsets,
    noise: NoiseModel,
    *,
    trials: int,
    cap: int,
    seed: int = 0,
) -> list[dict]:
    """Per gait (``((psi0_deg, zeta0) left, right)`` → the robot's runs), the robot's MJTF and the model's."""
    rows = []
    for stream, (legs, robot) in enumerate(sorted(robot_runs.items())):
        model_runs = simulated(model, offsets, legs, noise, trials=trials, cap=cap, seed=seed, stream=stream)
        rows.append({
            "controls": [list(pair) for pair in legs],
            "robot": robot.estimate(),
            "model": model_runs.estimate() | {"cap": cap, "capped": int(np.sum(~np.array(model_runs.failed)))},
        })  # fmt: skip
    return rows
