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
from sim_core.world.climb import first_touchdown
from sim_core.world.geometry import pack
from sim_core.world.reference import reference_world_jump
from sim_core.world.stride import world_orbit_batch
from sim_core.world.world import Side, World

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
    world_segments: int  # per side, of the world case's chute (docs/model.md §8)
    world_kernel_strides_per_s: float
    world_baseline_strides_per_s: float
    world_ratio: float
    world_max_abs_diff: float
    world_cost_vs_parallel: float  # one core: a world stride's time over a parallel-walls stride's

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
    say(f"world of {WORLD_SEGMENTS} segments a side: kernel on one core and the scipy twin")
    world = _world_case(model, schedule, gait.state, rng, baseline_strides, kernel_strides, repeats)
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
        world_segments=WORLD_SEGMENTS,
        world_kernel_strides_per_s=world["kernel"],
        world_baseline_strides_per_s=world["baseline"],
        world_ratio=world["kernel"] / world["baseline"],
        world_max_abs_diff=world["difference"],
        world_cost_vs_parallel=kernel_rate / world["kernel"],
    )


WORLD_SEGMENTS = 64  # a side of 32 footholds and the 32 stretches between them


def bench_world(d_hat: float) -> World:
    """The world case's chute: each side :data:`WORLD_SEGMENTS` segments from ``y = -4`` to 12
    [l0], rippling 0.1 l0 about parallel walls ``d_hat`` apart, grip alternating between the
    model's ``mu`` and 1.5, so most strides land (the ratio is of strides that do)."""
    heights = np.linspace(-4.0, 12.0, WORLD_SEGMENTS + 1)
    mu = np.resize([np.nan, 1.5], WORLD_SEGMENTS)
    sides = [
        Side(np.c_[sign * (d_hat / 2 + 0.1 * np.sin(2.3 * heights + phase)), heights], mu)
        for sign, phase in ((-1.0, 0.0), (1.0, 1.0))
    ]
    return World(*sides, name="bench")


def _world_case(model, schedule, gait_state, rng, baseline_strides, kernel_strides, repeats) -> dict:
    """Strides per second in :func:`bench_world`, the kernel on one core against the scipy twin
    (:mod:`sim_core.world.reference`, tolerance :data:`BASELINE_TOLERANCE`), from touchdowns on
    the left side at heights 0..4 with the gait's velocity perturbed; their largest difference."""
    world = bench_world(model.d_hat)
    sides = pack(world, model.mu)
    leg = schedule[0]
    starts = np.empty((baseline_strides, 4))
    segments = np.empty(baseline_strides, dtype=np.int64)
    for i, foot_y in enumerate(rng.uniform(0.0, 4.0, baseline_strides)):
        velocity = gait_state + rng.uniform(-0.1, 0.1, 2)
        starts[i], segments[i] = first_touchdown(model, world, schedule, velocity, foot_y)
    baseline_time, reference = _best_time(
        lambda: [reference_world_jump(model, world, start, 0, leg, leg, tol=BASELINE_TOLERANCE) for start in starts],
        repeats,
    )

    def run(count: int):
        states = np.zeros((count, 2, 4))
        states[:, 0] = np.resize(starts, (count, 4))
        on_side = np.zeros((count, 2), dtype=np.int64)
        on_segment = np.zeros((count, 2), dtype=np.int64)
        on_segment[:, 0] = np.resize(segments, count)
        status, completed = np.empty(count, dtype=np.int64), np.empty(count, dtype=np.int64)
        world_orbit_batch(schedule.as_array()[np.newaxis], 0, model.record(), sides, states, on_side, on_segment,
                          status, completed)  # fmt: skip
        return status, states[:, 1]

    status, landed = run(baseline_strides)  # compiles
    expected = np.array([outcome[0] for outcome in reference])
    both = (status == OK) & (expected == OK)
    if not np.array_equal(status, expected) or not both.any():
        raise RuntimeError("world kernel and its scipy twin disagree on which strides fail; the benchmark is void")
    difference = float(np.max(np.abs(landed[both] - np.array([outcome[1] for outcome in reference])[both])))
    threads = numba.get_num_threads()
    numba.set_num_threads(1)
    try:
        kernel_time, _ = _best_time(lambda: run(kernel_strides), repeats)
    finally:
        numba.set_num_threads(threads)
    return {"kernel": kernel_strides / kernel_time, "baseline": baseline_strides / baseline_time,
            "difference": difference}  # fmt: skip


def _best_time(work: Callable[[], object], repeats: int) -> tuple[float, object]:
    best = float("inf")
    result = None
    for _ in range(repeats):
        start = time.perf_counter()
        result = work()
        best = min(best, time.perf_counter() - start)
    return best, result
