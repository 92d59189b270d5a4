"""Fixtures the robot tests share: exceptions escaping threads (the link's fault tests), and a
simulated climb as the camera would see it (touchdown detection, recorded replays)."""

import threading

import pytest

from sim_core import ControlSchedule, find_fixed_point, get_preset, simulate_trajectory


@pytest.fixture
def thread_errors(monkeypatch):
    """Exceptions that escape any thread (they would print a traceback, not log one)."""
    errors = []
    monkeypatch.setattr(threading, "excepthook", errors.append)
    return errors


@pytest.fixture(scope="module")
def climb():
    """The paper's period-2 gait, 13 jumps (the record ends on the 13th touchdown, which therefore
    is not crossed), sampled at the camera's 100 Hz, in SI wall coordinates."""
    robot = get_preset("paper")
    model = robot.to_model()
    schedule = ControlSchedule.from_degrees([(30.0, 0.87), (30.0, 0.9)])
    gait = find_fixed_point(model, schedule, 2, (-0.8, -0.15))
    rate = 100.0 * robot.scales.time  # samples per sqrt(l0/g) for 100 Hz
    path = simulate_trajectory(model, schedule, gait.state, 13, sample_rate=rate)
    return robot, schedule, path, path.to_si(robot)
