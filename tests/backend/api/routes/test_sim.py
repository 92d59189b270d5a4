"""The panel's quick computations (backend/api/routes/sim.py)."""

import pytest

from sim_core.model.presets import get_preset
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
    # What the panel draws and labels with: the walls, and the units in metres and seconds.
    assert path["walls_x"] == pytest.approx([-1.21, 1.21])
    assert max(abs(x) for x in path["columns"]["x"]) < 1.21
    si = path["si"]
    assert si["preset"] == "paper" and si["l0_m"] == pytest.approx(0.2231, abs=1e-4)
    gravity = get_preset("paper").gravity  # reduced: the robot climbs a tilted air table
    assert si["time_s"] == pytest.approx((si["l0_m"] / gravity) ** 0.5), "the time unit sqrt(l0/g)"
    assert si["speed_m_per_s"] == pytest.approx(si["l0_m"] / si["time_s"])
