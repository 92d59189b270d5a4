"""Property tests: whatever valid input the map gets, it answers — an orbit or a named failure."""

import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from sim_core import ControlSchedule, Failure, ModelParams, iterate_map

finite = {"allow_nan": False, "allow_infinity": False}
controls = st.tuples(st.floats(1.0, 89.0, **finite), st.floats(0.05, 0.99, **finite))


@settings(max_examples=150, deadline=None)
@given(
    alpha=st.floats(0.5, 300.0, **finite),
    d_hat=st.floats(0.5, 5.0, **finite),
    damping=st.tuples(st.floats(0.0, 3.0, **finite), st.floats(0.0, 3.0, **finite)),
    mu=st.one_of(st.just(math.inf), st.floats(0.1, 5.0, **finite)),
    schedule=st.lists(controls, min_size=1, max_size=3),
    xdot=st.floats(-20.0, -1e-3, **finite),
    ydot=st.floats(-20.0, 20.0, **finite),
)
def test_map_always_answers(alpha, d_hat, damping, mu, schedule, xdot, ydot):
    model = ModelParams(alpha=alpha, d_hat=d_hat, c_zeta=damping[0], c_psi=damping[1], mu=mu)
    orbit = iterate_map(model, ControlSchedule.from_degrees(schedule), (xdot, ydot), 4)
    assert np.all(np.isfinite(orbit.states)) and np.all(np.isfinite(orbit.rises))
    assert np.all(orbit.states[1:, 0] < 0), "every section state flies toward the wall"
    if orbit.failure is None:
        assert orbit.jumps_completed == 4
    else:
        assert isinstance(orbit.failure, Failure) and orbit.failed_jump == orbit.jumps_completed + 1
        assert orbit.failure is not Failure.INVALID_STATE, "valid input fails physically, never numerically"
