"""The stance equations (sim_core.model.stance_equations) against physics: the energy balance (the damping
alone removes energy), Newton's law in Cartesian coordinates about the foot, and Hénon's trick."""

import math

import numpy as np
import pytest
from numpy.testing import assert_allclose

from sim_core.model.stance_equations import (
    COS_PSI,
    PSI,
    PSI_DOT,
    SIN_PSI,
    STATE_SIZE,
    TIME,
    ZETA,
    ZETA_DOT,
    rates,
    replace_item,
)

ALPHA = 77.6
RTOL_ROUNDING = 1e-12  # one evaluation of the equations: only rounding separates the two sides
ATOL_ROUNDING = 1e-10  # the same for sums of terms as large as alpha ~ 1e2
STATES = [  # (zeta, psi, zeta_dot, psi_dot): compressed and extending, leaning in and out
    (0.9, math.radians(30.0), -0.8, -0.5),
    (0.6, math.radians(50.0), 0.3, 1.7),
    (0.97, math.radians(-10.0), 2.0, -0.1),
]


def _state(zeta, psi, zeta_dot, psi_dot, time=0.25):
    return (zeta, psi, zeta_dot, psi_dot, math.cos(psi), math.sin(psi), time)


def _energy_rate(state, rate):
    """d/dt of E = (zeta_dot^2 + zeta^2 psi_dot^2)/2 + alpha (1 - zeta)^2/2 + zeta sin psi (per m g l0)."""
    zeta, psi, zeta_dot, psi_dot = state[ZETA], state[PSI], state[ZETA_DOT], state[PSI_DOT]
    return (
        zeta_dot * rate[ZETA_DOT]
        + zeta * psi_dot**2 * rate[ZETA]
        + zeta**2 * psi_dot * rate[PSI_DOT]
        - ALPHA * (1.0 - zeta) * rate[ZETA]
        + math.sin(psi) * rate[ZETA]
        + zeta * math.cos(psi) * rate[PSI]
    )


@pytest.mark.parametrize("polar", STATES)
@pytest.mark.parametrize(("c_zeta", "c_psi"), [(0.0, 0.0), (0.31, 0.31), (1.2, 0.05)])
def test_only_the_damping_changes_the_energy(polar, c_zeta, c_psi):
    state = _state(*polar)
    rate = rates(state, ALPHA, c_zeta, c_psi, TIME)
    zeta, zeta_dot, psi_dot = state[ZETA], state[ZETA_DOT], state[PSI_DOT]
    dissipated = -c_zeta * zeta_dot**2 - c_psi * (zeta * psi_dot) ** 2
    assert _energy_rate(state, rate) == pytest.approx(dissipated, abs=ATOL_ROUNDING)


@pytest.mark.parametrize("polar", STATES)
def test_the_polar_rates_are_newtons_law_about_the_foot(polar):
    """The body at r = zeta (cos psi, sin psi) from the foot: spring along the leg, gravity down,
    radial and tangential damping — the forces of the Cartesian reference (tests/sim_core/cartesian_reference.py)."""
    c_zeta, c_psi = 0.4, 0.2
    state = _state(*polar)
    zeta, psi, zeta_dot, psi_dot = polar
    rate = rates(state, ALPHA, c_zeta, c_psi, TIME)
    radial = np.array([math.cos(psi), math.sin(psi)])
    tangential = np.array([-math.sin(psi), math.cos(psi)])
    velocity = zeta_dot * radial + zeta * psi_dot * tangential
    force = (
        ALPHA * (1.0 - zeta) * radial
        - np.array([0.0, 1.0])
        - c_zeta * (velocity @ radial) * radial
        - c_psi * (velocity @ tangential) * tangential
    )
    # The acceleration of r, differentiated twice in polar coordinates.
    zeta_ddot, psi_ddot = rate[ZETA_DOT], rate[PSI_DOT]
    acceleration = (zeta_ddot - zeta * psi_dot**2) * radial + (zeta * psi_ddot + 2 * zeta_dot * psi_dot) * tangential
    assert_allclose(acceleration, force, rtol=0, atol=ATOL_ROUNDING)
    assert rate[ZETA] == zeta_dot and rate[PSI] == psi_dot and rate[TIME] == 1.0


@pytest.mark.parametrize("polar", STATES)
def test_cos_and_sin_turn_with_psi(polar):
    """The carried cos psi and sin psi change as the derivatives of cos and sin of psi do (central differences)."""
    state = _state(*polar)
    rate = rates(state, ALPHA, 0.3, 0.3, TIME)
    h = 1e-6
    psi, psi_dot = state[PSI], state[PSI_DOT]
    d_cos = (math.cos(psi + h * psi_dot) - math.cos(psi - h * psi_dot)) / (2 * h)
    d_sin = (math.sin(psi + h * psi_dot) - math.sin(psi - h * psi_dot)) / (2 * h)
    assert rate[COS_PSI] == pytest.approx(d_cos, abs=1e-8)
    assert rate[SIN_PSI] == pytest.approx(d_sin, abs=1e-8)


@pytest.mark.parametrize("independent", [ZETA, PSI, ZETA_DOT, PSI_DOT, COS_PSI, SIN_PSI])
def test_henons_trick_divides_by_the_new_variables_rate(independent):
    state = _state(*STATES[0])
    by_time = np.array(rates(state, ALPHA, 0.3, 0.3, TIME))
    by_other = np.array(rates(state, ALPHA, 0.3, 0.3, independent))
    expected = by_time / by_time[independent]
    expected[independent] = 1.0
    assert by_other[independent] == 1.0, "exactly 1 in the independent coordinate"
    assert_allclose(by_other, expected, rtol=RTOL_ROUNDING, atol=0)
    assert by_other[TIME] == pytest.approx(1.0 / by_time[independent], rel=RTOL_ROUNDING)


def test_a_variable_that_stands_still_cannot_be_independent():
    still = _state(0.9, 0.5, 0.0, -0.4)  # zeta_dot = 0: the leg neither extends nor shortens here
    assert not np.all(np.isfinite(rates(still, ALPHA, 0.3, 0.3, ZETA))), "inf or NaN: the caller's failed step"


def test_replace_item_changes_one_slot():
    values = tuple(float(i) for i in range(STATE_SIZE))
    for index in range(STATE_SIZE):
        replaced = replace_item(values, index, -1.0)
        assert replaced[index] == -1.0
        assert [v for i, v in enumerate(replaced) if i != index] == [v for i, v in enumerate(values) if i != index]
