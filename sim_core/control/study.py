"""The standard closed-loop benchmark: each controller climbing to a target under noise, every one
on the same noise draws, and how often and how well it holds the height.

A trial is a compiled loop (:func:`controlled_loop`) from the climbing gait's section state,
``jumps`` jumps with the noise of :mod:`sim_core.model.noise` drawn from the trial's seed (``seed0 + i``):
the draws are taken in the same order whatever the controller commands, so trial ``i`` meets the
same leg noise, pitch drift and state disturbances under every controller, and with the ``pid``
kind it is exactly :func:`sim_core.control.closed_loop.closed_loop_climb`'s run.

Per controller (:class:`ControllerOutcome`): failures and their codes; the height error over the
touchdowns after a run first reaches 90% of its climb (from its first touchdown to the target),
pooled over every run while it is up, as an RMS and a median absolute error; ``rise_jumps``, the
median first touchdown at 90%; the share of commands the law had to clip to the leg's range; and
the law's own time per jump (:func:`controller_time_us`, the compiled step alone, not the jump);
the jumps done by each failed trial and the first trials' climbs whole, to draw. The trials run in
chunks of seeds (:func:`study_chunk`) through a chunk map (:mod:`sim_core.chunks`), as a job on the
service's worker or a Dask cluster; the outcome does not depend on the chunking.
"""

from __future__ import annotations

import math
import time
from collections import Counter
from dataclasses import dataclass, field

import numpy as np

from sim_core._jit import kernel
from sim_core.chunks import ChunkMap, Progress, chunk_slices, in_process
from sim_core.control.controllers import control_step, start_memory
from sim_core.control.laws import Controller
from sim_core.control.loop_step import LOOP_STATE_SIZE, body_height, loop_jump, start_loop
from sim_core.model.failures import OK, Failure
from sim_core.model.integrate import STATE_SIZE
from sim_core.model.noise import NoiseModel
from sim_core.model.noise_rules import seed_trial
from sim_core.model.params import ModelParams
from sim_core.model.poincare import check_jumps, check_section_state
from sim_core.model.validation import check_range

RISE_FRACTION = 0.9  # a run has risen once it has climbed 90% of the way to its target
MAX_TRIALS = 100_000
CHUNK_SEEDS = 50  # trials per chunk: a progress step of about a tenth of a second at 400 jumps
EXAMPLES = 3  # the first trials' climbs kept whole, to show


@dataclass(frozen=True)
class ControllerOutcome:
    """One controller's trials. Heights and errors in l0 (:meth:`to_dict` gives metres)."""

    name: str
    trials: int
    failure_codes: dict[str, int]
    height_errors: np.ndarray  # pooled over the runs, after each first reached 90% of its climb
    rise_jumps: np.ndarray  # per run that rose: the first touchdown at 90% of the climb
    commands: int
    saturated: int
    us_per_jump: float
    failure_jumps: np.ndarray = field(default_factory=lambda: np.empty(0, dtype=np.int64))  # jumps done, per failure
    examples: tuple[np.ndarray, ...] = ()  # the first trials' touchdown heights [l0], up to EXAMPLES
    jumps: int = 0  # each trial's length: a run that survives it is censored there

    @property
    def failures(self) -> int:
        return sum(self.failure_codes.values())

    def jumps_to_failure(self) -> tuple[float, float]:
        """The mean jumps to failure of the trials, each survivor counted at the trials' length
        (the restricted mean: the MJTF itself when every trial fails, a lower bound otherwise),
        and its 95% interval's half-width (normal approximation)."""
        lasted = np.concatenate([self.failure_jumps, np.full(self.trials - self.failures, self.jumps)]).astype(float)
        half_width = 1.96 * lasted.std(ddof=1) / math.sqrt(lasted.size) if lasted.size > 1 else math.inf
        return float(lasted.mean()), float(half_width)

    def to_dict(self, leg_length: float) -> dict:
        """The ``parkour control-study --json`` entry; ``leg_length`` [m] converts heights."""
        errors = self.height_errors
        lasted, lasted_ci95 = self.jumps_to_failure()
        return {
            "name": self.name,
            "trials": self.trials,
            "failures": self.failures,
            "failure_rate": self.failures / self.trials,
            "failure_codes": dict(sorted(self.failure_codes.items())),
            "height_rms_m": float(np.sqrt(np.mean(errors**2))) * leg_length if errors.size else None,
            "height_median_abs_m": float(np.median(np.abs(errors))) * leg_length if errors.size else None,
            "rise_jumps": float(np.median(self.rise_jumps)) if self.rise_jumps.size else None,
            "us_per_jump": self.us_per_jump,
            "saturated_fraction": self.saturated / self.commands if self.commands else 0.0,
            "mean_jumps_to_failure": lasted,
            "mean_jumps_to_failure_ci95": lasted_ci95,
            "survived": self.trials - self.failures,
        }

    @classmethod
    def merged(cls, parts: list[ControllerOutcome], us_per_jump: float | None = None) -> ControllerOutcome:
        """One controller's chunks of trials (in seed order) as one outcome."""
        codes: Counter[str] = Counter()
        for part in parts:
            codes.update(part.failure_codes)
        return cls(
            name=parts[0].name,
            trials=sum(part.trials for part in parts),
            failure_codes=dict(codes),
            height_errors=np.concatenate([part.height_errors for part in parts]),
            rise_jumps=np.concatenate([part.rise_jumps for part in parts]),
            commands=sum(part.commands for part in parts),
            saturated=sum(part.saturated for part in parts),
            us_per_jump=parts[0].us_per_jump if us_per_jump is None else us_per_jump,
            failure_jumps=np.concatenate([part.failure_jumps for part in parts]),
            examples=tuple(example for part in parts for example in part.examples)[:EXAMPLES],
            jumps=parts[0].jumps,
        )


def control_study(
    model: ModelParams,
    controllers: list[Controller],
    start,
    start_zeta0: float,
    jumps: int,
    seed0: int,
    seeds: int,
    noise: NoiseModel,
    *,
    chunk_map: ChunkMap = in_process,
    progress: Progress | None = None,
    chunk_seeds: int = CHUNK_SEEDS,
) -> list[ControllerOutcome]:
    """Every controller on trials ``seed0 .. seed0 + seeds - 1``, each from section state ``start``,
    its first touchdown at the controller's nominal leg angle and ``start_zeta0``. The trials run
    as chunks of ``chunk_seeds`` seeds per controller through ``chunk_map`` (:mod:`sim_core.chunks`);
    results do not depend on it."""
    state = check_section_state(start)
    jumps = check_jumps(jumps)
    check_range("seeds", seeds, 1, MAX_TRIALS, low_open=False, high_open=False)
    check_range("seed0", seed0, 0, 2**32 - seeds, low_open=False, high_open=False)
    check_range("start_zeta0", start_zeta0, 0.0, 1.0)
    if not controllers:
        raise ValueError("no controller to study")
    pieces = chunk_slices(seeds, chunk_seeds)
    arguments = [
        (model, controller, state, start_zeta0, jumps, seed0 + piece.start, piece.stop - piece.start, noise)
        for controller in controllers
        for piece in pieces
    ]
    parts = chunk_map(study_chunk, arguments, progress)
    return [
        ControllerOutcome.merged(parts[i * len(pieces) : (i + 1) * len(pieces)], controller_time_us(controller))
        for i, controller in enumerate(controllers)
    ]


def study_chunk(
    model: ModelParams,
    controller: Controller,
    state: np.ndarray,
    start_zeta0: float,
    jumps: int,
    seed0: int,
    seeds: int,
    noise: NoiseModel,
) -> ControllerOutcome:
    """One controller on trials ``seed0 .. seed0 + seeds - 1`` (a chunk of :func:`control_study`);
    its ``us_per_jump`` is left at 0 (timed once, for the whole study)."""
    kind, parameters = controller.kernel_args()
    codes: Counter[str] = Counter()
    errors, rises, failed_at, examples = [], [], [], []
    commands = saturated = 0
    target = controller.target
    for seed in range(seed0, seed0 + seeds):
        height = np.full(jumps + 1, math.nan)
        clipped = np.zeros(jumps, dtype=np.bool_)
        status, completed = controlled_loop(
            state[0], state[1], math.radians(controller.psi0_deg), start_zeta0, kind, parameters, seed,
            noise.record(), model.record(), height, clipped,
        )  # fmt: skip
        if status != OK:
            codes[Failure(status).code] += 1
            failed_at.append(completed)
        reached = height[: completed + 1]
        if seed < seed0 + EXAMPLES:
            examples.append(reached)
        issued = completed + (status != OK)  # a failed jump's command was issued too
        commands += issued
        saturated += int(np.count_nonzero(clipped[:issued]))
        risen = np.flatnonzero((reached - reached[0]) >= RISE_FRACTION * (target - reached[0]))
        if risen.size:
            rises.append(int(risen[0]))
            if status == OK:
                errors.append(target - reached[risen[0] :])
    return ControllerOutcome(
        name=controller.name,
        trials=seeds,
        failure_codes=dict(codes),
        height_errors=np.concatenate(errors) if errors else np.empty(0),
        rise_jumps=np.array(rises, dtype=float),
        commands=commands,
        saturated=saturated,
        us_per_jump=0.0,
        failure_jumps=np.array(failed_at, dtype=np.int64),
        examples=tuple(examples),
        jumps=jumps,
    )


def controller_time_us(controller: Controller, seconds: float = 0.05) -> float:
    """The law's own CPU time per jump [µs]: its compiled step over about ``seconds`` of touchdowns,
    best of 3 (a model-predictive law takes a thousand times a PID's, so the count is set by a
    first run of 100). The thread's CPU time, not the wall clock: a busy machine does not slow it
    (the wall clock read deadbeat at 1-2.5 ms a jump under load, 128 µs of CPU)."""
    kind, parameters = controller.kernel_args()
    _time_steps(kind, parameters, 10)  # compiled before the clock starts
    began = time.thread_time()
    _time_steps(kind, parameters, 100)
    steps = int(min(max(100 * seconds / max(time.thread_time() - began, 1e-9), 100), 1_000_000))
    best = math.inf
    for _ in range(3):
        began = time.thread_time()
        _time_steps(kind, parameters, steps)
        best = min(best, time.thread_time() - began)
    return 1e6 * best / steps


@kernel
def _time_steps(kind, parameters, steps):
    memory = start_memory(kind, 0.6, 0.9)
    total = 0.0
    for k in range(steps):  # heights, pitches and states that vary, so no step is folded away
        vary = 1e-7 * (k % 11)
        psi0, zeta0, _ = control_step(kind, parameters, memory, 0.3 + vary, 10 * vary, -0.9 + vary, -0.2, k % 2 == 0)
        total += psi0 + zeta0
    return total


@kernel
def controlled_loop(xdot, ydot, first_psi0, first_zeta0, kind, parameters, seed, noise, model, height, saturated):
    """One trial under controller ``(kind, parameters)`` with the ``noise`` and ``model`` records
    (:meth:`NoiseModel.record`, :meth:`ModelParams.record`); fills ``height`` per touchdown reached
    [l0] and ``saturated`` per command. Returns ``(status, jumps completed)``."""
    seed_trial(seed)
    no_record = np.empty((0, STATE_SIZE))
    state = np.empty(LOOP_STATE_SIZE)
    start_loop(state, kind, xdot, ydot, first_psi0, first_zeta0, noise)
    jumps = height.shape[0] - 1
    for k in range(jumps + 1):
        height[k] = body_height(state)
        if k == jumps:
            break
        status, saturated[k] = loop_jump(state, k, kind, parameters, noise, model, no_record)
        if status != OK:
            return status, k
    return OK, jumps
