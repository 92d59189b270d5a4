"""``run_benchmark`` reports every figure of the contract (values are measured, never asserted)."""

import pytest

from sim_core.bench import run_benchmark
from sim_core.model.validation import ParameterError

CONTRACT = {  # issue 3's: what `parkour bench --json` promised first
    "kernel_strides_per_s",
    "baseline_strides_per_s",
    "ratio",
    "max_abs_diff",
    "batch_strides_per_s",
    "cores",
}
BASIN_EXTENSION = {  # issue 4's
    "basin_grid",
    "basin_jumps",
    "basin_seconds",
    "basin_jumps_computed",
    "basin_baseline_projected_seconds",
    "basin_speedup",
}
WORLD_EXTENSION = {  # issue 41's: a world's stride against its scipy twin
    "world_segments",
    "world_kernel_strides_per_s",
    "world_baseline_strides_per_s",
    "world_ratio",
    "world_max_abs_diff",
    "world_cost_vs_parallel",
}


def test_benchmark_reports_all_figures():
    stages = []
    result = run_benchmark(  # one keyword a line, like presets.py's PhysicalParams: alike in shape only
        baseline_strides=5,
        kernel_strides=50,
        batch_strides=50,
        repeats=1,
        basin_grid=8,
        basin_jumps=10,
        progress=stages.append,
    )
    assert set(result.to_dict()) == CONTRACT | BASIN_EXTENSION | WORLD_EXTENSION
    assert 0 < result.basin_jumps_computed <= 8 * 8 * 10
    assert result.max_abs_diff <= 1e-8
    assert result.ratio == pytest.approx(result.kernel_strides_per_s / result.baseline_strides_per_s)
    assert result.cores >= 1 and stages
    assert result.world_max_abs_diff <= 1e-8 and result.world_segments == 64
    assert result.world_ratio == pytest.approx(result.world_kernel_strides_per_s / result.world_baseline_strides_per_s)


def test_benchmark_rejects_bad_sizes():
    with pytest.raises(ParameterError, match="baseline_strides"):
        run_benchmark(baseline_strides=0)
