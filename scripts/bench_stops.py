"""What a stopped service leaves behind, and how long a restarted one takes to read fast.

Each try starts ``parkour serve`` in a session of its own (so every process it starts, however it
is re-parented later, shares the session id), submits a long MJTF job and a queued one through the
Python client, waits until the first is computing (``--at job``; ``--at start``: only until health
first answers, its workers still starting), then stops the service with ``--signal`` (``TERM`` or
``KILL``) and counts the session's processes still alive, and their memory (RSS), after
``--after`` seconds. Survivors are then killed, so one try does not pollute the next.

It also reports, per try, the start's seconds to the first health answer, to a health of
``"ok"`` (older services answer ``"ok"`` at once), and to the answer of a ``GET /api/v1/runs``
asked then (``runs_s``; ``runs_answer_s``: how long that one took).

    python scripts/bench_stops.py [--signal TERM|KILL] [--at job|start] [--tries 5] [--after 5] [--json]
"""

from __future__ import annotations

import argparse
import json
import os
import signal
import socket
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import httpx
import psutil

from parkourlab import Client

START_TIMEOUT_S = 120.0  # [s] a cold numba cache on a loaded 2-core machine
LONG_JOB = {"zeta0s": [round(0.85 + 0.01 * i, 2) for i in range(11)], "trials": 4096, "cap": 1000}
QUEUED_JOB = {"zeta0s": [0.9], "trials": 64, "cap": 300}


def free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


def session_processes(session: int) -> list[psutil.Process]:
    """The live processes of session ``session`` (zombies left out: they hold no memory)."""
    found = []
    for process in psutil.process_iter(["status"]):
        try:
            if os.getsid(process.pid) == session and process.info["status"] != psutil.STATUS_ZOMBIE:
                found.append(process)
        except (ProcessLookupError, PermissionError):
            continue
    return found


def one_try(data_dir: Path, stop: signal.Signals, after: float, at: str) -> dict:
    port = free_port()
    url = f"http://127.0.0.1:{port}"
    command = [sys.executable, "-m", "cli", "serve", "--data-dir", str(data_dir), "--port", str(port)]
    command += ["--view-port", "0"]
    start = time.monotonic()
    service = subprocess.Popen(command, start_new_session=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    seconds: dict[str, float] = {}
    while "ok" not in seconds and not (at == "start" and "health" in seconds):
        if time.monotonic() - start > START_TIMEOUT_S:
            raise RuntimeError("the service did not become healthy")
        try:
            health = httpx.get(f"{url}/api/v1/health", timeout=5).json()
            seconds.setdefault("health", time.monotonic() - start)
            if health["status"] == "ok":
                seconds["ok"] = time.monotonic() - start
        except httpx.HTTPError:
            pass
        time.sleep(0.1)
    if at == "job":
        asked = time.monotonic()
        httpx.get(f"{url}/api/v1/runs", timeout=START_TIMEOUT_S).raise_for_status()
        seconds["runs"] = time.monotonic() - start
        seconds["runs_answer"] = time.monotonic() - asked
        with Client(url, token=(data_dir / "api_token").read_text().strip()) as client:
            running = client.submit_mjtf(**LONG_JOB, seed=1)
            client.submit_mjtf(**QUEUED_JOB, seed=2)
            while client.job(running)["completed"] == 0:
                time.sleep(0.2)
    before = len(session_processes(service.pid))
    service.send_signal(stop)
    service.wait(60)
    time.sleep(after)
    survivors = session_processes(service.pid)
    memory = 0
    names = []
    for process in survivors:
        try:
            memory += process.memory_info().rss
            names.append(" ".join(process.cmdline())[:100])
        except psutil.NoSuchProcess:
            continue
    for process in survivors:
        try:
            process.kill()
        except psutil.NoSuchProcess:
            continue
    return {
        "processes_before": before, "survivors": len(survivors), "survivor_mb": round(memory / 2**20),
        "survivor_commands": names, **{f"{name}_s": round(value, 2) for name, value in seconds.items()},
    }  # fmt: skip


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--signal", choices=["TERM", "KILL"], default="TERM")
    parser.add_argument("--tries", type=int, default=5)
    parser.add_argument("--after", type=float, default=5.0, help="[s] after the service ended, count survivors")
    parser.add_argument(
        "--at",
        choices=["job", "start"],
        default="job",
        help="stop mid-job (a long job running, one queued), or at the first health answer",
    )
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args()
    stop = signal.Signals[f"SIG{args.signal}"]
    tries = []
    with tempfile.TemporaryDirectory(prefix="parkour-stops-") as scratch:
        for index in range(args.tries):
            tries.append(one_try(Path(scratch) / str(index), stop, args.after, args.at))
            if not args.json:
                print(json.dumps(tries[-1]), flush=True)
    summary = {
        "signal": args.signal, "at": args.at, "tries": args.tries,
        "tries_with_survivors": sum(t["survivors"] > 0 for t in tries),
        "survivors": sum(t["survivors"] for t in tries), "survivor_mb": sum(t["survivor_mb"] for t in tries),
    }  # fmt: skip
    print(json.dumps({"summary": summary, "tries": tries} if args.json else summary))


if __name__ == "__main__":
    main()
