"""The services on a real, migrated SQLite file in a temporary directory; no app, no HTTP."""

import pytest

from backend.repositories import runs as run_store
from backend.schemas import ExperimentCreate
from backend.services import experiments, runs
from backend.store.models import Run
from tests.backend.services.bodies import run_body


@pytest.fixture
def make_run(session):
    """``make_run(zeta0=..., psi0_deg=..., **fields)``: a simulated run stored through the runs
    service, as the session holds its row."""

    def make(zeta0: float = 0.9, psi0_deg: float = 30.0, **fields) -> Run:
        return run_store.get_run(session, runs.create_run(session, run_body(zeta0, psi0_deg, **fields)).id)

    return make


@pytest.fixture
def service(sessions):
    """The robot service, closed afterwards."""
    from backend.services.robot import RobotService  # only the robot tests load the robot side

    service = RobotService(sessions)
    yield service
    service.close()


@pytest.fixture
def connected(service, virtual):
    """The robot service connected to the virtual robot (disarmed)."""
    from backend.schemas import RobotConnect

    robot, tracker_port = virtual
    status = service.connect(RobotConnect(url=robot.url, tracker_port=tracker_port))
    assert status["state"] == "disarmed", status
    return service


@pytest.fixture
def stored_runs(session, make_run):
    """Five runs: zeta0 0.86 .. 0.94 at psi0 = 30°, the middle one tagged and in an experiment,
    and one slipping run at psi0 = 60°."""
    experiment = experiments.create(session, ExperimentCreate(name="energy"))
    runs = {}
    for zeta0 in (0.86, 0.88, 0.9, 0.92, 0.94):
        tags = ["middle"] if zeta0 == 0.9 else []
        runs[zeta0] = make_run(zeta0=zeta0, tags=tags, experiment_id=experiment.id if zeta0 == 0.9 else None)
    runs["slip"] = make_run(psi0_deg=60.0, tags=["middle"])
    return experiment, runs
