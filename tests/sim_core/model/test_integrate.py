"""The stance kernel on its own: energy conservation and exact event landing."""

import math

import numpy as np
import pytest

from sim_core.model.failures import COLLAPSE, OK
from sim_core.model.integrate import COLLAPSE_ZETA, PSI, PSI_DOT, STATE_SIZE, TIME, ZETA, ZETA_DOT, stance
from sim_core.model.stride import touchdown_polar_state

STANCE_ENERGY_RTOL = 1e-9


def _energy(nodes, alpha):
    zeta, psi, zeta_dot, psi_dot = nodes[:, ZETA], nodes[:, PSI], nodes[:, ZETA_DOT], nodes[:, PSI_DOT]
    return 0.5 * (zeta_dot**2 + zeta**2 * psi_dot**2) + 0.5 * alpha * (1 - zeta) ** 2 + zeta * np.sin(psi)


@pytest.mark.parametrize(
    ("alpha", "psi0_deg", "zeta0", "velocity"),
    [
        (77.6, 30.0, 0.9, (-0.93, -0.17)),
        (20.0, 45.0, 0.8, (-1.5, 0.8)),
        (150.0, 20.0, 0.95, (-0.5, -1.0)),
    ],
)
def test_stance_conserves_energy_without_damping(alpha, psi0_deg, zeta0, velocity):
    psi0 = math.radians(psi0_deg)
    zeta_dot, psi_dot = touchdown_polar_state(velocity[0], velocity[1], psi0, zeta0)
    record = np.empty((5000, STATE_SIZE))
    final = np.empty(STATE_SIZE)
    status, rows = stance(zeta0, psi0, zeta_dot, psi_dot, alpha, 0.0, 0.0, math.inf, final, record)
    assert status == OK
    energy = _energy(record[:rows], alpha)
    assert np.max(np.abs(energy - energy[0])) <= STANCE_ENERGY_RTOL * abs(energy[0])
    assert final[ZETA] == 1.0 and final[ZETA_DOT] > 0, "lift-off lands exactly on zeta = 1"
    assert record[rows - 1, TIME] == final[TIME]


def test_damping_dissipates_energy():
    psi0 = math.radians(30.0)
    zeta_dot, psi_dot = touchdown_polar_state(-0.93, -0.17, psi0, 0.9)
    record = np.empty((5000, STATE_SIZE))
    final = np.empty(STATE_SIZE)
    status, rows = stance(0.9, psi0, zeta_dot, psi_dot, 77.6, 0.3, 0.3, math.inf, final, record)
    assert status == OK
    energy = _energy(record[:rows], 77.6)
    assert np.all(np.diff(energy) < 0)


@pytest.mark.parametrize("zeta0", [1e-5, COLLAPSE_ZETA])
def test_touchdown_already_collapsed_fails_at_once(zeta0):
    """Found by the API fuzzer: a leg retracted below the collapse length used to "land" the
    collapse event behind the touchdown, so the recorded stance ran backwards in time."""
    psi0 = math.radians(30.0)
    zeta_dot, psi_dot = touchdown_polar_state(-0.93, -0.17, psi0, zeta0)
    record = np.empty((50, STATE_SIZE))
    final = np.empty(STATE_SIZE)
    status, rows = stance(zeta0, psi0, zeta_dot, psi_dot, 77.6, 0.0, 0.0, math.inf, final, record)
    assert status == COLLAPSE
    assert rows == 1 and final[TIME] == 0.0
