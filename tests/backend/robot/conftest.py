"""Fixtures the robot link's fault tests share."""

import threading

import pytest


@pytest.fixture
def thread_errors(monkeypatch):
    """Exceptions that escape any thread (they would print a traceback, not log one)."""
    errors = []
    monkeypatch.setattr(threading, "excepthook", errors.append)
    return errors
