"""Request bodies the service tests build, as the API would after validating JSON."""

from backend.schemas import LegIn, RunCreate, StateIn

START = StateIn(xdot=-0.93, ydot=-0.17)


def run_body(zeta0: float = 0.9, psi0_deg: float = 30.0, **fields) -> RunCreate:
    """A short simulated run (4 jumps) of one leg's controls; ``fields`` override the rest of the body."""
    body = {"controls": [LegIn(psi0_deg=psi0_deg, zeta0=zeta0)], "start": START, "jumps": 4}
    return RunCreate(**(body | fields))
