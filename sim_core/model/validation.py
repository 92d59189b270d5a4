"""One place that checks numbers against their allowed ranges.

Every error names the field and the allowed range, so the CLI, the API and the GUI can
show it to a person as is.
"""

from __future__ import annotations

import math

from sim_core.model.errors import ParameterError

__all__ = ["ParameterError", "check_range"]


def check_range(
    field: str,
    value: float,
    low: float = -math.inf,
    high: float = math.inf,
    *,
    low_open: bool = True,
    high_open: bool = True,
    allow_inf: bool = False,
) -> float:
    """Return ``float(value)`` if it lies in the interval, else raise :class:`ParameterError`.

    Bounds are open by default; ``low_open=False`` makes the lower bound inclusive.
    NaN is always rejected; infinities only with ``allow_inf``.
    """
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise ParameterError(field, f"must be a number, got {value!r}") from None
    if math.isnan(number) or (math.isinf(number) and not allow_inf):
        raise ParameterError(field, f"must be a finite number, got {number}")
    below = number <= low if low_open else number < low
    above = number >= high if high_open else number > high
    if below or above:
        left = "(" if low_open else "["
        right = ")" if high_open else "]"
        raise ParameterError(field, f"must be in {left}{_fmt(low)}, {_fmt(high)}{right}, got {number:g}")
    return number


def check_interval(field: str, interval, low: float = -math.inf, high: float = math.inf) -> tuple[float, float]:
    """``(low, high)`` of a pair within the open bounds with ``low < high``, else :class:`ParameterError`."""
    try:
        first, second = (check_range(field, value, low, high) for value in interval)
    except (TypeError, ValueError) as error:
        if isinstance(error, ParameterError):
            raise
        raise ParameterError(field, f"must be a pair (low, high), got {interval!r}") from None
    if not first < second:
        within = "" if math.isinf(low) and math.isinf(high) else f" within ({_fmt(low)}, {_fmt(high)})"
        raise ParameterError(
            field, f"must be a non-empty interval with low < high{within}, got [{first:g}, {second:g}]"
        )
    return first, second


def _fmt(bound: float) -> str:
    if math.isinf(bound):
        return "inf" if bound > 0 else "-inf"
    return f"{bound:g}"
