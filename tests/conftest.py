"""Shared fixtures: the paper's model, the gaits the paper reports (docs/model.md §5), the databases
(SQLite, and PostgreSQL where a server can be had), the virtual robot."""

import os
import socket

import pytest

from sim_core import ControlSchedule, ModelParams, get_preset
from sim_core.model.noise import NO_NOISE
from tests.helpers import free_port

# Starlette's TestClient calls the service "testserver" (its Host header): allowed here as a
# deployment would name its host (backend/api/security.py refuses Host names not on the list).
os.environ["PARKOUR_ALLOWED_HOSTS"] = "testserver"


# [s] an e-stop's budget where a test checks that it gets through: a hang guard (5 s ran out on a
# machine loaded 4x)
PATIENT_ESTOP_S = 15.0


@pytest.fixture
def patient_estop(monkeypatch):
    """The e-stop's budget widened to PATIENT_ESTOP_S, the link's and the service's wait for it
    alike: for a test that checks that an e-stop is acknowledged and what follows, not that it is
    within 150 ms on a machine that may be loaded. That bound is the realtime part's
    (test_link.py's fast e-stop, test_estop_load.py)."""
    from backend.robot.link import RobotLink
    from backend.services import robot

    monkeypatch.setattr(RobotLink, "estop_timeout", PATIENT_ESTOP_S)
    monkeypatch.setattr(robot, "ANSWER_WAIT", PATIENT_ESTOP_S + robot.LATCH_SAVE_WAIT)


# [s] the robot's first telemetry on a connect, outside the realtime part: a hang guard. The
# service's 3 s ran out for an in-process robot rig under two busy loops on two cores (load 9).
PATIENT_CONNECT_S = 8.0


@pytest.fixture(autouse=True)
def patient_connect(request, monkeypatch):
    """Every test but the realtime part's waits PATIENT_CONNECT_S for the robot's first telemetry
    on a connect: what follows a connect is what they test, not the robot's answer within 3 s on a
    machine that may be loaded (the realtime part keeps the service's 3 s)."""
    if request.node.get_closest_marker("realtime") is None:
        from backend.robot import supervisor

        monkeypatch.setattr(supervisor, "CONNECT_TIMEOUT", PATIENT_CONNECT_S)


@pytest.fixture(scope="session")
def paper() -> ModelParams:
    return get_preset("paper").to_model()


@pytest.fixture(scope="session")
def symmetric() -> ControlSchedule:
    """psi0 = 30°, zeta0 = 0.9: the paper's stable period-1 climbing gait."""
    return ControlSchedule.from_degrees([(30.0, 0.9)])


@pytest.fixture(scope="session")
def alternating() -> ControlSchedule:
    """psi0 = 30°/30°, zeta0 = 0.87/0.90: the paper's stable period-2 gait."""
    return ControlSchedule.from_degrees([(30.0, 0.87), (30.0, 0.9)])


@pytest.fixture(scope="session")
def compute():
    """The service's compute worker pools, shared by every test's app (a worker's start, about a
    second, is paid once per session); stopped at the end."""
    from backend.services.quick_calls import warm_up
    from backend.workers.pools import Compute  # only the tests that use the service load it

    pools = Compute()
    # The kernels a quick call needs, loaded once here with no time limit, as the service's own
    # warm-up does at start: on an empty numba cache (a fresh CI machine) compiling them inside a
    # test's first call, beside another worker compiling too, ran past the 60 s a quick call gets.
    pools.quick.run(warm_up, timeout=None)
    yield pools
    pools.close()


@pytest.fixture(scope="session")
def postgres():
    """The session's PostgreSQL databases (tests/postgres.py), or a skip saying why there are none."""
    from tests.postgres import postgres_databases, why_unavailable

    reason = why_unavailable()
    if reason:
        pytest.skip(reason)
    with postgres_databases() as databases:
        yield databases


@pytest.fixture(params=["sqlite", "postgresql"])
def database_url(request, tmp_path) -> str | None:
    """Each test that asks for it runs twice: on SQLite (None: the data directory's own file) and on a
    fresh PostgreSQL database of its own (skipped where no server can be had)."""
    if request.param == "sqlite":
        yield None
        return
    with request.getfixturevalue("postgres").fresh() as url:
        yield url


@pytest.fixture(params=["sqlite", "postgresql"])
def empty_database_url(request, tmp_path) -> str:
    """An empty database's URL, on SQLite and on PostgreSQL (each test runs on both; skipped where no
    PostgreSQL server can be had): for tests of the migrations themselves."""
    if request.param == "sqlite":
        from backend.store.database import sqlite_url

        yield sqlite_url(tmp_path)
        return
    with request.getfixturevalue("postgres").fresh(migrated=False) as url:
        yield url


@pytest.fixture
def virtual(request):
    """``(robot, tracker_port)``: a noiseless virtual robot streaming its tracker poses to a free
    local UDP port; stopped afterwards. It climbs at 4x real time unless the test is marked
    ``robot_speed(s)``: a closed loop must answer each touchdown within the next stance, so a
    test of one runs in real time, as the robot does, not with a quarter of the robot's margin."""
    from backend.robot.virtual import VirtualRobot  # only the tests that use the robot load the backend

    marker = request.node.get_closest_marker("robot_speed")
    speed = marker.args[0] if marker else 4.0
    port = free_port(socket.SOCK_DGRAM)
    robot = VirtualRobot(tracker_to=("127.0.0.1", port), noise=NO_NOISE, speed=speed, seed=2).start()
    yield robot, port
    robot.stop()


@pytest.fixture
def sessions(tmp_path):
    """A real, migrated SQLite store in a temporary directory: the session factory the service
    hands its parts (``sessionmaker``, expire_on_commit off)."""
    from backend.store.database import make_engine, migrate, session_factory, sqlite_url

    engine = make_engine(sqlite_url(tmp_path))
    migrate(engine)
    yield session_factory(engine)
    engine.dispose()
