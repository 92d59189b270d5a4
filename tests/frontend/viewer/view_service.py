"""The 3D view inside the service, for the tests that drive it: a run to store, and waiting.

The fixtures that start it (``service``, ``browsers``) are in tests/frontend/viewer/conftest.py.
"""

import time

RUN = {
    "controls": [{"psi0_deg": 30, "zeta0": 0.87}, {"psi0_deg": 30, "zeta0": 0.9}],
    "start": {"xdot": -0.8, "ydot": -0.15},
    "jumps": 6,
}


def wait_for(condition, timeout=10.0):
    """Wait until ``condition()`` holds, at most ``timeout`` [s] (then fail the test)."""
    deadline = time.monotonic() + timeout
    while not condition():
        assert time.monotonic() < deadline, "timed out"
        time.sleep(0.02)
