"""``parkour bench``: speed and accuracy of the compiled map against the scipy baseline.

Both run side by side in one process over the same section states (perturbations of the
paper preset's period-1 gait, seeded), so the ratio is meaningful on a shared, noisy machine:
the kernel's strides per second on one core, the baseline's (:mod:`sim_core.model.reference`,
DOP853 at rtol = atol = 1e-10), their ratio, the largest difference between their next
section states and rises, and the batch throughput on all cores. It also times the basin of
that gait over a 200 x 200 grid x 60 jumps (issue 4's target: under 10 s on 2 cores) and
projects the baseline's time for the same jumps.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import asdict, dataclass

import numba
import numpy as np

from sim_core.basins.basin import BasinGrid, compute_basin
from sim_core.model.controls import ControlSchedule
from sim_core.model.failures import OK
from sim_core.model.poincare import iterate_map_batch
from sim_core.model.presets import PAPER_GAITS, START_GUESS, get_preset
from sim_core.model.reference import reference_jumps
from sim_core.model.validation import check_range
from sim_core.section.gait_search import gait_of

BASELINE_TOLERANCE = 1e-10


@dataclass(frozen=True)
class BenchResult:
    """Measured figures; ``to_dict`` is the ``parkour bench --json`` contract."""

    kernel_strides_per_s: float
    baseline_strides_per_s: float
    ratio: float
    max_abs_diff: float
    batch_strides_per_s: float
    cores: int
    basin_grid: int
    basin_jumps: int
    basin_seconds: float
    basin_jumps_computed: int
    basin_baseline_projected_seconds: float
    basin_speedup: float

    def to_dict(self) -> dict:
        return asdict(self)


def run_benchmark(
    *,
    baseline_strides: int = 200,
    kernel_strides: int = 20_000,
    batch_strides: int = 100_000,
    repeats: int = 3,
    basin_grid: int = 200,
    basin_jumps: int = 60,
    seed: int = 0,
    progress: Callable[[str], None] | None = None,
) -> BenchResult:
    """Measure; each timing is the best of ``repeats``. ``progress`` receives stage names."""
    for name, value in (
        ("baseline_strides", baseline_strides),
        ("kernel_strides", kernel_strides),
        ("batch_strides", batch_strides),
        ("repeats", repeats),
        ("basin_grid", basin_grid),
        ("basin_jumps", basin_jumps),
    ):
        check_range(name, value, 1, 10_000_000, low_open=False, high_open=False)
    say = progress or (lambda _stage: None)
    model = get_preset("paper").to_model()
    schedule = ControlSchedule.from_degrees(PAPER_GAITS["period 1"])
    leg = schedule[0]
    gait = gait_of(model, schedule, guess=START_GUESS)
    rng = np.random.default_rng(seed)
    states = gait.state + rng.uniform(-0.1, 0.1, size=(baseline_strides, 2))

    say("compiling the kernel")
    iterate_map_batch(model, schedule, states[:2], 1)

    say("scipy baseline")
    baseline_time, (ref_status, ref_states, ref_rises) = _best_time(
        lambda: reference_jumps(model, states, leg, leg, rtol=BASELINE_TOLERANCE, atol=BASELINE_TOLERANCE),
        repeats,
    )
    kernel_batch = iterate_map_batch(model, schedule, states, 1)
    agree = (ref_status == OK) & (kernel_batch.status == OK)
    if not np.array_equal(ref_status, kernel_batch.status) or not agree.any():
        raise RuntimeError("kernel and baseline disagree on which strides fail; the benchmark is void")
    max_abs_diff = float(
        max(
            np.max(np.abs(kernel_batch.states[agree, 1] - ref_states[agree])),
            np.max(np.abs(kernel_batch.rises[agree, 0] - ref_rises[agree])),
        )
    )

    many = np.resize(states, (kernel_strides, 2))
    threads = numba.get_num_threads()
    say("kernel on one core")
    numba.set_num_threads(1)
    try:
        kernel_time, _ = _best_time(lambda: iterate_map_batch(model, schedule, many, 1), repeats)
    finally:
        numba.set_num_threads(threads)
    say(f"batch on {threads} cores")
    batch = np.resize(states, (batch_strides, 2))
    batch_time, _ = _best_time(lambda: iterate_map_batch(model, schedule, batch, 1), repeats)

    say(f"basin {basin_grid}x{basin_grid} x {basin_jumps} jumps on {threads} cores")
    grid = BasinGrid.around(gait.state, basin_grid)
    compute_basin(model, schedule, gait, BasinGrid.around(gait.state, 2), max_jumps=basin_jumps)  # compile
    basin_time, basin = _best_time(lambda: compute_basin(model, schedule, gait, grid, max_jumps=basin_jumps), 1)

    kernel_rate = kernel_strides / kernel_time
    baseline_rate = baseline_strides / baseline_time
    baseline_basin_time = basin.jumps_computed / baseline_rate
    return BenchResult(
        kernel_strides_per_s=kernel_rate,
        baseline_strides_per_s=baseline_rate,
        ratio=kernel_rate / baseline_rate,
        max_abs_diff=max_abs_diff,
        batch_strides_per_s=batch_strides / batch_time,
        cores=threads,
        basin_grid=basin_grid,
        basin_jumps=basin_jumps,
        basin_seconds=basin_time,
        basin_jumps_computed=basin.jumps_computed,
        basin_baseline_projected_seconds=baseline_basin_time,
        basin_speedup=baseline_basin_time / basin_time,
    )


def _best_time(work: Callable[[], object], repeats: int) -> tuple[float, object]:
    best = float("inf")
    result = None
    for _ in range(repeats):
        start = time.perf_counter()
        result = work()
        best = min(best, time.perf_counter() - start)
    return best, result
