"""The workers on a real, migrated SQLite file in a temporary directory, with runs stored through
the runs service; no app, no HTTP."""

import pytest

from backend.services import runs
from backend.store.models import Run
from tests.backend.services.bodies import run_body


@pytest.fixture
def make_run(sessions):
    """``make_run(zeta0=..., psi0_deg=..., **fields)``: a simulated run stored through the runs service."""

    def make(zeta0: float = 0.9, psi0_deg: float = 30.0, **fields) -> Run:
        with sessions() as session:
            return runs.create_run(session, run_body(zeta0, psi0_deg, **fields))

    return make
