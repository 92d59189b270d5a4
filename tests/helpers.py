"""Helpers that test modules share: free ports, the real service started as ``parkour serve``, and
clients that keep its request thread pool full."""

from __future__ import annotations

import json
import os
import signal
import socket
import subprocess
import sys
import tempfile
import threading
import time
from collections import Counter
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import httpx
import pytest

ROOT = Path(__file__).resolve().parents[1]  # the checkout
SERVICE_START_TIMEOUT = 60.0  # [s] a cold start compiles nothing, but CI machines are slow
SERVICE_START_TRIES = 5  # ports a service started on a free port tries, each taken before it bound it
POOL_FILLERS = 45  # more requests than the service has request threads (backend/api/app.py), and anyio's 40
# A /sim/map call of 1000 jumps: a few ms of kernel under the service's kernel lock, back to back.
MAP_BODY = {"controls": [{"psi0_deg": 30, "zeta0": 0.87}], "start": {"xdot": -0.9, "ydot": -0.2}, "jumps": 1000}
# A heavy MJTF job: 11 energy levels x 4096 trials of up to 1000 jumps, 1408 chunks of 32 trials
# (tens of ms each, under the kernel lock, on every core numba has): a minute or more; cancel it.
HEAVY_JOB = {"kind": "mjtf", "zeta0s": [round(0.85 + 0.01 * i, 2) for i in range(11)], "trials": 4096, "cap": 1000}


def free_port(kind: socket.SocketKind = socket.SOCK_STREAM) -> int:
    """A port on 127.0.0.1 that nothing listens on now (TCP by default; ``socket.SOCK_DGRAM`` for UDP)."""
    with socket.socket(socket.AF_INET, kind) as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


def start_service(
    data_dir: Path, port: int, *options: str, tree: Path | None = None, log: Path | None = None
) -> subprocess.Popen:
    """``parkour serve --data-dir DATA_DIR --port PORT OPTIONS...`` in a subprocess, returned once
    ``/api/v1/health`` answers and the service that answers takes DATA_DIR's token; the caller ends it
    (``terminate``, or ``SIGKILL`` to test a crash). The process's ``port`` is the port it serves on.

    ``port`` 0: a free one, and another if another program takes it before the service binds it (the
    service exits, address already in use, or someone else's service answers there), up to
    SERVICE_START_TRIES ports. ``tree``: the service's code from another checkout (a benchmark's
    base revision), run with this venv; ``log``: a file for its stderr (default: a temporary one)."""
    for _ in range(SERVICE_START_TRIES if port == 0 else 1):
        process = _serve(data_dir, port or free_port(), options, tree, log)
        if process is not None:
            return process
    if port:
        pytest.fail(f"port {port} is another program's")
    pytest.fail(f"the service found no free port in {SERVICE_START_TRIES} tries: each was taken before it bound it")


def _serve(data_dir: Path, port: int, options, tree: Path | None, log: Path | None) -> subprocess.Popen | None:
    """:func:`start_service` on ``port``: the process once it serves there; None if the port was
    another program's (ours ended); a test failure, with the end of its stderr, if it ended or hung."""
    command = [sys.executable, "-m", "cli", "serve", "--data-dir", str(data_dir), "--port", str(port), *options]
    env = None if tree is None else dict(os.environ, PYTHONPATH=str(tree))
    answer = None
    with tempfile.TemporaryFile() if log is None else log.open("w+b") as stderr:
        process = subprocess.Popen(command, cwd=tree, env=env, stdout=subprocess.DEVNULL, stderr=stderr)
        process.port = port
        deadline = time.monotonic() + SERVICE_START_TIMEOUT
        while time.monotonic() < deadline and process.poll() is None:
            if (answer := _whose(data_dir, port)) == "ours":
                return process
            if answer == "another's":  # ours cannot bind the port: it exits, or is ended here
                break
            time.sleep(0.2)
        if process.poll() is None:
            process.kill()
        process.wait()
        stderr.seek(0)
        said = stderr.read().decode(errors="replace")
    if answer == "another's" or "address already in use" in said.lower():
        return None
    if process.returncode == -signal.SIGKILL:
        pytest.fail(f"the service did not start within {SERVICE_START_TIMEOUT:g} s: {said[-2000:]}")
    pytest.fail(f"the service ended at start ({process.returncode}): {said[-2000:]}")


def _whose(data_dir: Path, port: int) -> str | None:
    """Who answers ``/api/v1/health`` on ``port``: ``"ours"`` (its ``/api/v1/auth`` takes DATA_DIR's
    token; a service older than that route is taken as ours), ``"another's"``, or None (nobody yet)."""
    base = f"http://127.0.0.1:{port}/api/v1"
    try:
        if httpx.get(f"{base}/health", timeout=1).status_code != 200:
            return None
        token = (data_dir / "api_token").read_text().strip()
        accepted = httpx.get(f"{base}/auth", headers={"Authorization": f"Bearer {token}"}, timeout=1).status_code
    except (httpx.HTTPError, OSError):  # nobody listens yet; or no token yet: not ours answering
        return None
    return "another's" if accepted == 401 else "ours"


@contextmanager
def served(data_dir: Path, *options: str) -> Iterator[tuple[str, str]]:
    """``parkour serve`` over ``data_dir`` on a free port (:func:`start_service`): its base URL and
    its API token. Afterwards SIGTERM, and it must end within 30 s (a hang fails the test)."""
    process = start_service(data_dir, 0, *options)
    try:
        yield f"http://127.0.0.1:{process.port}", (data_dir / "api_token").read_text().strip()
    finally:
        process.terminate()
        process.wait(30)


def start_robot_sim(port: int, tracker_port: int, *options: str) -> subprocess.Popen:
    """``parkour robot-sim --port PORT --tracker 127.0.0.1:TRACKER_PORT OPTIONS...`` (the virtual
    robot) in a subprocess, returned once it listens; the caller ends it."""
    command = [sys.executable, "-m", "cli", "robot-sim", "--port", str(port),
               "--tracker", f"127.0.0.1:{tracker_port}", *options]  # fmt: skip
    process = subprocess.Popen(command, cwd=ROOT, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.monotonic() + SERVICE_START_TIMEOUT
    while time.monotonic() < deadline:
        try:
            socket.create_connection(("127.0.0.1", port), timeout=1).close()
            return process
        except OSError:
            time.sleep(0.1)
    process.kill()
    process.wait()
    raise RuntimeError(f"parkour robot-sim did not listen on {port} within {SERVICE_START_TIMEOUT:g} s")


def stop_processes(*processes: subprocess.Popen, timeout: float = 30.0) -> None:
    """SIGTERM each, wait up to ``timeout`` [s] for it to end, and kill it if it has not."""
    for process in processes:
        process.terminate()
        try:
            process.wait(timeout)
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait()


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


class MapLoad:
    """``clients`` threads, each POSTing ``/api/v1/sim/map`` to ``base`` back to back until :meth:`stop`.

    With more clients than the request thread pool has threads, the pool stays full: every sync
    route waits for a thread. :attr:`in_flight` is how many requests are out now; :meth:`stop`
    returns how each was answered (status codes, or the httpx error's name)."""

    def __init__(self, base: str, clients: int = POOL_FILLERS, body: dict = MAP_BODY):
        self.base, self.body, self.clients = base, body, clients
        self.in_flight = 0
        self.answered: Counter = Counter()
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self._threads = [
            threading.Thread(target=self._client, name=f"map-load-{i}", daemon=True) for i in range(clients)
        ]

    def start(self) -> MapLoad:
        for thread in self._threads:
            thread.start()
        return self

    def stop(self, timeout: float = 60.0) -> Counter:
        self._stop.set()
        deadline = time.monotonic() + timeout
        for thread in self._threads:
            thread.join(max(0.0, deadline - time.monotonic()))
        return self.answered

    def _client(self) -> None:
        with httpx.Client(base_url=self.base, timeout=60) as client:
            while not self._stop.is_set():
                with self._lock:
                    self.in_flight += 1
                try:
                    answer = client.post("/api/v1/sim/map", json=self.body).status_code
                except httpx.HTTPError as error:
                    answer = type(error).__name__
                with self._lock:
                    self.in_flight -= 1
                    self.answered[answer] += 1


LOAD_SCRIPT = """
import json, sys, time
from tests.helpers import MapLoad
load = MapLoad(sys.argv[1], int(sys.argv[2])).start()
deadline = time.monotonic() + 60
while load.in_flight < load.clients or sum(load.answered.values()) < load.clients:
    if time.monotonic() > deadline:
        sys.exit("the load's clients did not all get going")
    time.sleep(0.01)
print("ready", flush=True)
sys.stdin.read()
print(json.dumps({str(key): count for key, count in load.stop().items()}))
"""


def start_map_load(base: str, clients: int = POOL_FILLERS) -> subprocess.Popen:
    """:class:`MapLoad` in a process of its own (its threads do not compete for this process's GIL),
    returned once every client has a request out and all have been answered at least once."""
    command = [sys.executable, "-c", LOAD_SCRIPT, base, str(clients)]
    process = subprocess.Popen(command, stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True, cwd=ROOT)
    if process.stdout.readline().strip() != "ready":
        process.kill()
        raise RuntimeError("the /sim/map load did not get going")
    return process


def stop_map_load(process: subprocess.Popen) -> dict:
    """End a :func:`start_map_load` process; returns how its requests were answered (status: count)."""
    answered, _ = process.communicate("", timeout=120)
    return json.loads(answered)
