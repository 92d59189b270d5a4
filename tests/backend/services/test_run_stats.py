"""Summary statistics of a group of runs (backend/services/run_stats.py), against scipy and numpy."""

import numpy as np
import pytest
from scipy import stats as scipy_stats

from backend.services.run_stats import stats, t_975


@pytest.mark.parametrize("degrees_of_freedom", [1, 2, 3, 5, 10, 29, 30, 31, 45, 100, 1000, 100_000])
def test_students_quantile_matches_scipy(degrees_of_freedom):
    assert t_975(degrees_of_freedom) == pytest.approx(scipy_stats.t.ppf(0.975, degrees_of_freedom), abs=1e-4)


def test_no_quantile_without_a_degree_of_freedom():
    with pytest.raises(ValueError, match="at least 1"):
        t_975(0)


@pytest.mark.parametrize("seed", [1, 2, 3])
@pytest.mark.parametrize("count", [2, 3, 7, 40])
def test_stats_from_the_moments_match_the_values(seed, count):
    values = np.random.default_rng(seed).normal(0.6, 0.3, count)
    got = stats(count, float(values.mean()), float((values**2).mean()), float(values.min()), float(values.max()))
    assert got["mean"] == pytest.approx(values.mean()) and got["std"] == pytest.approx(values.std(), abs=1e-12)
    low, high = scipy_stats.t.interval(0.95, count - 1, loc=values.mean(), scale=scipy_stats.sem(values))
    assert (got["ci95_low"], got["ci95_high"]) == pytest.approx((low, high), abs=1e-4)
    assert (got["min"], got["max"]) == (values.min(), values.max())


def test_one_run_has_no_interval_and_rounding_never_makes_a_negative_variance():
    one = stats(1, 0.5, 0.25, 0.5, 0.5)
    assert one["std"] == 0.0 and one["ci95_low"] is None and one["ci95_high"] is None
    assert stats(3, 0.1, 0.01 - 1e-18, 0.1, 0.1)["std"] == 0.0
