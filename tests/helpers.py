"""Helpers that test modules share: free ports, and the real service started as ``parkour serve``."""

from __future__ import annotations

import socket
import subprocess
import sys
import threading
import time
from pathlib import Path

import httpx
import pytest

SERVICE_START_TIMEOUT = 60.0  # [s] a cold start compiles nothing, but CI machines are slow


def free_port(kind: socket.SocketKind = socket.SOCK_STREAM) -> int:
    """A port on 127.0.0.1 that nothing listens on now (TCP by default; ``socket.SOCK_DGRAM`` for UDP)."""
    with socket.socket(socket.AF_INET, kind) as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


def start_service(data_dir: Path, port: int, *options: str) -> subprocess.Popen:
    """``parkour serve --data-dir DATA_DIR --port PORT OPTIONS...`` in a subprocess, returned once
    ``/api/v1/health`` answers; the caller ends it (``terminate``, or ``SIGKILL`` to test a crash)."""
    command = [sys.executable, "-m", "cli", "serve", "--data-dir", str(data_dir), "--port", str(port), *options]
    process = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.monotonic() + SERVICE_START_TIMEOUT
    while time.monotonic() < deadline:
        try:
            if httpx.get(f"http://127.0.0.1:{port}/api/v1/health", timeout=1).status_code == 200:
                return process
        except httpx.HTTPError:
            time.sleep(0.2)
    process.kill()
    process.wait()
    pytest.fail(f"the service did not start within {SERVICE_START_TIMEOUT:g} s")


def answer_within(seconds: float, call, *args):
    """``call(*args)``'s result, or a test failure if it has not returned after ``seconds`` — so a
    call that regresses into a hang fails instead of hanging the suite (the thread is left behind)."""
    box: list = []
    thread = threading.Thread(target=lambda: box.append(call(*args)), name="answer-within", daemon=True)
    thread.start()
    thread.join(seconds)
    if thread.is_alive():
        pytest.fail(f"{getattr(call, '__name__', call)} did not answer within {seconds:g} s")
    if not box:
        pytest.fail(f"{getattr(call, '__name__', call)} raised (see the thread's traceback)")
    return box[0]
