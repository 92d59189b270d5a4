"""Shared fixtures: the paper's model and the gaits the paper reports (docs/model.md §5)."""

import pytest

from sim_core import ControlSchedule, ModelParams, get_preset


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
