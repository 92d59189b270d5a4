"""Summary statistics of a group of runs from the moments the database sums: mean, population
standard deviation, range and the 95% confidence interval of the mean (Student's t).

A group of runs is often a handful of seeds of one setting: the normal approximation's 1.96
would make their interval too narrow (with 3 runs, t is 4.30), so the quantile is Student's, from
a table up to 30 degrees of freedom and the Cornish-Fisher expansion past it (within 1e-4).
"""

from __future__ import annotations

import math

# Student's t, two-sided 95% (the 0.975 quantile), for 1 to 30 degrees of freedom.
T_975 = (12.7062, 4.3027, 3.1824, 2.7764, 2.5706, 2.4469, 2.3646, 2.3060, 2.2622, 2.2281,
         2.2010, 2.1788, 2.1604, 2.1448, 2.1314, 2.1199, 2.1098, 2.1009, 2.0930, 2.0860,
         2.0796, 2.0739, 2.0687, 2.0639, 2.0595, 2.0555, 2.0518, 2.0484, 2.0452, 2.0423)  # fmt: skip
Z_975 = 1.959964


def t_975(degrees_of_freedom: int) -> float:
    """The 0.975 quantile of Student's t with ``degrees_of_freedom`` (≥ 1)."""
    if degrees_of_freedom < 1:
        raise ValueError(f"degrees of freedom must be at least 1, got {degrees_of_freedom}")
    if degrees_of_freedom <= len(T_975):
        return T_975[degrees_of_freedom - 1]
    z, n = Z_975, degrees_of_freedom
    return z + (z**3 + z) / (4 * n) + (5 * z**5 + 16 * z**3 + 3 * z) / (96 * n**2)


def stats(count: int, mean: float, mean_square: float, low: float, high: float) -> dict:
    """:class:`~backend.schemas.runs.Stats` of ``count`` values from their mean, the mean of their
    squares, smallest and largest: the population std over the group, and the 95% interval of the
    mean from the sample std (none for fewer than two values)."""
    variance = max(mean_square - mean * mean, 0.0)
    result = {"mean": mean, "std": math.sqrt(variance), "min": low, "max": high, "ci95_low": None, "ci95_high": None}
    if count > 1:
        half_width = t_975(count - 1) * math.sqrt(variance * count / (count - 1)) / math.sqrt(count)
        result |= {"ci95_low": mean - half_width, "ci95_high": mean + half_width}
    return result
