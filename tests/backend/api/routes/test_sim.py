"""The panel's quick computations (backend/api/routes/sim.py)."""

import pytest

from tests.backend.api.bodies import RUN


def test_quick_fixed_point(client):
    body = {"controls": [{"psi0_deg": 30, "zeta0": 0.9}], "guess": {"xdot": -0.9, "ydot": -0.2}}
    gait = client.post("/api/v1/sim/fixed-point", json=body).json()
    assert gait["period"] == 1 and gait["stable"] and gait["max_abs_eigenvalue"] == pytest.approx(0.8486, abs=1e-4)


def test_quick_trajectory(client):
    body = {k: RUN[k] for k in ("controls", "start")} | {"jumps": 2, "rate": 50}
    path = client.post("/api/v1/sim/trajectory", json=body).json()
    assert path["units"] == "nondimensional" and len(path["touchdown_times"]) == 3
    assert len(path["columns"]["x"]) == len(path["columns"]["time"]) > 50 and path["failure"] is None
