"""The e-stop latch against kill -9 right after the answer: is the press on disk when it says so?

``parkour serve`` (a subprocess, SQLite in one data directory kept across the tries) connects to the
virtual robot (``parkour robot-sim``, its own process); each try resets a held latch, presses the
e-stop (``POST /api/v1/robot/estop``, no token, as the panel does), kills the service with SIGKILL
the moment the answer arrives, and reads the latch file the next start would read
(``estop-latch.json``). ``--unconnected`` presses with no robot connected instead. Reported: tries,
answers that said latched, files that said held after the kill (the finding: 4 of 7 forgotten).

``--tree`` runs another checkout's service (e.g. ``git worktree add /tmp/base HEAD~1``) with this
venv, for the before and after side by side.

Usage, from the checkout's root:

    PYTHONPATH=. python scripts/bench_latch_kill.py [--tries 20] [--unconnected] [--tree PATH] [--json]
"""

from __future__ import annotations

import argparse
import json
import os
import signal
import socket
import tempfile
import time
from pathlib import Path

import httpx

from tests.helpers import free_port, start_robot_sim, start_service, stop_processes

TIMEOUT_S = 30.0  # [s] any one request: a bound, not a measurement


def latch_file(data_dir: Path) -> dict | None:
    path = data_dir / "estop-latch.json"
    try:
        return json.loads(path.read_text())
    except (OSError, ValueError):
        return None


def one_try(data_dir: Path, robot_port: int | None, tracker_port: int, tree: Path | None) -> dict:
    port = free_port()
    service = start_service(data_dir, port, "--no-view", tree=tree)
    base = f"http://127.0.0.1:{port}/api/v1"
    token = (data_dir / "api_token").read_text().strip()
    auth = {"Authorization": f"Bearer {token}"}
    try:
        with httpx.Client(timeout=TIMEOUT_S) as client:
            if robot_port is not None:
                body = {"url": f"socket://127.0.0.1:{robot_port}", "tracker_port": tracker_port}
                client.post(f"{base}/robot/connect", json=body, headers=auth).raise_for_status()
                if client.get(f"{base}/robot").json()["estop"]["latched"]:
                    reset = client.post(f"{base}/robot/reset", headers=auth)
                    assert reset.status_code == 200, reset.text
            else:
                (data_dir / "estop-latch.json").unlink(missing_ok=True)  # released before the press
            answer = client.post(f"{base}/robot/estop").json()
            os.kill(service.pid, signal.SIGKILL)  # the moment the answer is in
    finally:
        service.kill()
        service.wait()
    saved = latch_file(data_dir)
    return {
        "acknowledged": answer["acknowledged"],
        "answer_latched": answer["estop"]["latched"],
        "answer_durable": answer["estop"].get("durable"),
        "file_held": bool(saved and saved.get("held")),
        "reason": answer.get("reason"),  # why not acknowledged (None when it was)
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--tries", type=int, default=20)
    parser.add_argument("--unconnected", action="store_true", help="press with no robot connected")
    parser.add_argument("--tree", type=Path, default=None, help="another checkout's service")
    parser.add_argument("--json", action="store_true")
    options = parser.parse_args()
    data_dir = Path(tempfile.mkdtemp(prefix="parkour-latch-kill-"))
    tracker_port = free_port(socket.SOCK_DGRAM)
    robot = None if options.unconnected else start_robot_sim(free_port(), tracker_port, "--noise", "off")
    robot_port = None if robot is None else int(robot.args[robot.args.index("--port") + 1])
    tries = []
    try:
        for _ in range(options.tries):
            tries.append(one_try(data_dir, robot_port, tracker_port, options.tree))
            if not options.json:
                print(tries[-1], flush=True)
            time.sleep(0.2)
    finally:
        if robot is not None:
            stop_processes(robot)
    summary = {
        "tree": str(options.tree or "this checkout"),
        "connected": robot is not None,
        "tries": len(tries),
        "acknowledged": sum(t["acknowledged"] for t in tries),
        "answered_latched": sum(t["answer_latched"] for t in tries),
        "held_after_kill": sum(t["file_held"] for t in tries),
        "forgotten": sum(t["answer_latched"] and not t["file_held"] for t in tries),
    }
    print(json.dumps({**summary, "each": tries} if options.json else summary, indent=1))


if __name__ == "__main__":
    main()
