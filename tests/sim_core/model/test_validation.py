"""check_range (sim_core.model.validation): open and closed bounds, NaN and infinities, and messages that
name the field and the interval."""

import math

import pytest

from sim_core.model.validation import ParameterError, check_range


def test_a_value_inside_comes_back_as_a_float():
    value = check_range("zeta0", 1, 0.0, 2.0)
    assert value == 1.0 and type(value) is float


@pytest.mark.parametrize(
    ("value", "options", "message"),
    [
        (0.0, {}, "zeta0: must be in (0, 1), got 0"),
        (1.0, {}, "zeta0: must be in (0, 1), got 1"),
        (1.0, {"high_open": False}, None),
        (0.0, {"low_open": False}, None),
        (-0.5, {"low_open": False}, "zeta0: must be in [0, 1), got -0.5"),
        (1.5, {"low_open": False, "high_open": False}, "zeta0: must be in [0, 1], got 1.5"),
    ],
)
def test_bounds_are_open_unless_closed(value, options, message):
    if message is None:
        assert check_range("zeta0", value, 0.0, 1.0, **options) == value
    else:
        with pytest.raises(ParameterError) as error:
            check_range("zeta0", value, 0.0, 1.0, **options)
        assert str(error.value) == message and error.value.field == "zeta0"


def test_nan_is_always_rejected():
    for allow_inf in (False, True):
        with pytest.raises(ParameterError, match=r"^mu: must be a finite number, got nan$"):
            check_range("mu", math.nan, allow_inf=allow_inf)


def test_infinity_only_when_allowed_and_unbounded_sides_read_inf():
    with pytest.raises(ParameterError, match="finite"):
        check_range("mu", math.inf, 0.0)
    assert check_range("mu", math.inf, 0.0, high_open=False, allow_inf=True) == math.inf
    with pytest.raises(ParameterError, match=r"must be in \(0, inf\), got inf$"):
        check_range("mu", math.inf, 0.0, allow_inf=True)  # an open bound at inf leaves inf out
    with pytest.raises(ParameterError, match=r"^alpha: must be in \(0, inf\), got -1$"):
        check_range("alpha", -1.0, 0.0)
    with pytest.raises(ParameterError, match=r"must be in \(-inf, 0\), got 3$"):
        check_range("offset", 3.0, high=0.0)


@pytest.mark.parametrize("value", ["fast", None, [1.0], object()])
def test_something_not_a_number_is_named_as_given(value):
    with pytest.raises(ParameterError) as error:
        check_range("alpha", value, 0.0)
    assert error.value.message == f"must be a number, got {value!r}"


def test_numeric_strings_are_read_as_numbers():
    assert check_range("alpha", "77.6", 0.0) == 77.6


def test_an_interval_is_a_pair_in_order_within_its_bounds():
    from sim_core.model.validation import check_interval

    assert check_interval("xdot_range", (0.5, 2)) == (0.5, 2.0)
    with pytest.raises(ParameterError, match=r"xdot_range: must be a non-empty interval with low < high, got \[2, 1\]"):
        check_interval("xdot_range", (2, 1))
    with pytest.raises(ParameterError, match=r"zeta0_range: must be a non-empty interval .* within \(0, 1\)"):
        check_interval("zeta0_range", (0.9, 0.8), 0.0, 1.0)
    with pytest.raises(ParameterError, match=r"zeta0_range: must be in \(0, 1\), got 1.5"):
        check_interval("zeta0_range", (0.5, 1.5), 0.0, 1.0)
    with pytest.raises(ParameterError, match="psi0_range: must be a pair"):
        check_interval("psi0_range", 3.0)
