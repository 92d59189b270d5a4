"""``run_benchmark`` reports every figure of the contract (values are measured, never asserted)."""

import pytest

from sim_core.bench import run_benchmark
from sim_core.validation import ParameterError


def test_benchmark_reports_all_figures():
    stages = []
    result = run_benchmark(baseline_strides=5, kernel_strides=50, batch_strides=50, repeats=1, progress=stages.append)
    assert set(result.to_dict()) == {
        "kernel_strides_per_s",
        "baseline_strides_per_s",
        "ratio",
        "max_abs_diff",
        "batch_strides_per_s",
        "cores",
    }
    assert result.max_abs_diff <= 1e-8
    assert result.ratio == pytest.approx(result.kernel_strides_per_s / result.baseline_strides_per_s)
    assert result.cores >= 1 and stages


def test_benchmark_rejects_bad_sizes():
    with pytest.raises(ParameterError, match="baseline_strides"):
        run_benchmark(baseline_strides=0)
