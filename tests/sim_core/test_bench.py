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
    assert set(result.to_dict()) == CONTRACT | BASIN_EXTENSION
    assert 0 < result.basin_jumps_computed <= 8 * 8 * 10
    assert result.max_abs_diff <= 1e-8
    assert result.ratio == pytest.approx(result.kernel_strides_per_s / result.baseline_strides_per_s)
    assert result.cores >= 1 and stages


def test_benchmark_rejects_bad_sizes():
    with pytest.raises(ParameterError, match="baseline_strides"):
        run_benchmark(baseline_strides=0)
