"""Heartbeat gaps as the robot sees them, and the e-stop's round trip, idle and under load.

docs/protocol.md §3: the PC sends HEARTBEAT at least every 0.2 s; the robot disarms after 1 s
without a frame. This measures what arrives at the robot: the service (``parkour serve --no-view``,
SQLite in a temporary directory) connects to ``socket://`` on a tap in this process, which forwards
every byte to and from the virtual robot (``parkour robot-sim``, its own process) and timestamps each
frame the PC sends, decoded with the link's own frame and message codecs. For each phase — idle,
then ``--clients`` clients (default 20 and 50) POSTing ``/api/v1/sim/map`` back to back from another
process — it reports the gaps between consecutive heartbeats (median, p99, max; an ESTOP counts as
the heartbeat it replaces, as during a press: ``heartbeat_only_gaps`` leaves them out) and presses the
e-stop (no token) ``--presses`` times: the HTTP round trip (p50, p99, max) and how many the robot
acknowledged; a RESET (the token's call) follows each press.

Usage, from the checkout's root:

    PYTHONPATH=. python scripts/bench_heartbeat.py [--seconds 20] [--clients 20 50] [--presses 20]
        [--tree PATH] [--json]

``--tree`` runs another checkout's service (e.g. a ``git worktree`` of the base revision) with this
venv, for a side-by-side before/after.
"""

from __future__ import annotations

import argparse
import itertools
import json
import math
import socket
import statistics
import tempfile
import threading
import time
from pathlib import Path

import httpx

from backend.robot.messages import Command, Kind, decode
from backend.robot.xbee import TX_REQUEST, FrameError, FrameParser, parse_tx_request
from tests.helpers import free_port, start_map_load, start_robot_sim, start_service, stop_map_load, stop_processes

TIMEOUT_S = 60.0  # [s] any one request: a bound, not a measurement
PRESS_EVERY_S = 0.5  # [s] between e-stop presses within a phase


class Tap:
    """A TCP relay between the service's link and the virtual robot that timestamps the PC's frames."""

    def __init__(self, robot_port: int):
        self.robot_port = robot_port
        self.listener = socket.create_server(("127.0.0.1", 0))
        self.port = self.listener.getsockname()[1]
        self.frames: list[tuple[float, Kind | None]] = []  # (monotonic time, command kind or None)
        self._lock = threading.Lock()
        threading.Thread(target=self._accept, name="tap", daemon=True).start()

    def since(self, start: float) -> list[tuple[float, Kind | None]]:
        with self._lock:
            return [frame for frame in self.frames if frame[0] >= start]

    def _accept(self) -> None:
        while True:
            try:
                pc, _ = self.listener.accept()
            except OSError:
                return
            try:
                robot = socket.create_connection(("127.0.0.1", self.robot_port))
            except OSError:  # the robot has gone (the bench is ending): the service's reconnect finds nothing
                pc.close()
                continue
            for sock in (pc, robot):
                sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
            threading.Thread(target=self._pump, args=(pc, robot, True), daemon=True).start()
            threading.Thread(target=self._pump, args=(robot, pc, False), daemon=True).start()

    def _pump(self, source: socket.socket, sink: socket.socket, from_pc: bool) -> None:
        parser = FrameParser()
        while True:
            try:
                chunk = source.recv(65536)
            except OSError:
                chunk = b""
            if not chunk:
                for sock in (source, sink):
                    sock.close()
                return
            arrived = time.monotonic()
            if from_pc:
                for data in parser.feed(chunk):
                    self._note(arrived, data)
            try:
                sink.sendall(chunk)
            except OSError:
                return

    def _note(self, arrived: float, data: bytes) -> None:
        if data[0] != TX_REQUEST:
            return
        try:
            message = decode(parse_tx_request(data)[2])
        except (FrameError, ValueError):
            return
        with self._lock:
            self.frames.append((arrived, message.kind if isinstance(message, Command) else None))


def nearest_rank(ordered: list[float], fraction: float) -> float:
    """The ``fraction`` percentile of sorted values by nearest rank (never below the median of few)."""
    return ordered[max(0, math.ceil(fraction * len(ordered)) - 1)]


def gaps_ms(frames: list[tuple[float, Kind | None]], kinds: set[Kind]) -> dict:
    times = [t for t, k in frames if k in kinds]
    gaps = sorted((b - a) * 1000 for a, b in itertools.pairwise(times))
    if not gaps:
        return {"n": 0}
    return {
        "n": len(gaps),
        "median_ms": round(statistics.median(gaps), 1),
        "p99_ms": round(nearest_rank(gaps, 0.99), 1),
        "max_ms": round(gaps[-1], 1),
    }


def round_trips_ms(values: list[float]) -> dict:
    values = sorted(values)
    return {
        "n": len(values),
        "p50_ms": round(statistics.median(values), 1),
        "p99_ms": round(nearest_rank(values, 0.99), 1),
        "max_ms": round(values[-1], 1),
    }


def phase(client: httpx.Client, auth: dict, tap: Tap, seconds: float, presses: int) -> dict:
    """Heartbeat gaps over ``seconds``, with ``presses`` e-stops (each followed by a RESET) spread over it."""
    start = time.monotonic()
    http, acknowledged = [], 0
    for _ in range(presses):
        started = time.perf_counter()
        answer = client.post("/api/v1/robot/estop").json()
        http.append((time.perf_counter() - started) * 1000)
        acknowledged += bool(answer["acknowledged"])
        client.post("/api/v1/robot/reset", headers=auth)
        time.sleep(max(0.0, PRESS_EVERY_S - (time.perf_counter() - started)))
    time.sleep(max(0.0, start + seconds - time.monotonic()))
    frames = tap.since(start)
    return {
        # The robot's watchdog slots: a heartbeat, or the ESTOP the PC sends in its place (§3).
        "heartbeat_gaps": gaps_ms(frames, {Kind.HEARTBEAT, Kind.ESTOP}),
        "heartbeat_only_gaps": gaps_ms(frames, {Kind.HEARTBEAT}),
        "estop": {**round_trips_ms(http), "acknowledged": acknowledged} if http else {"n": 0},
    }


def measure(seconds: float, clients: list[int], presses: int, tree: Path | None) -> dict:
    result = {}
    with tempfile.TemporaryDirectory(prefix="bench-heartbeat-") as data:
        port, tracker_port, robot_port = free_port(), free_port(socket.SOCK_DGRAM), free_port()
        service = start_service(Path(data), port, "--no-view", tree=tree)
        robot = start_robot_sim(robot_port, tracker_port)
        tap = Tap(robot_port)
        base = f"http://127.0.0.1:{port}"
        client = httpx.Client(base_url=base, timeout=TIMEOUT_S)
        auth = {"Authorization": f"Bearer {(Path(data) / 'api_token').read_text().strip()}"}
        try:
            body = {"url": f"socket://127.0.0.1:{tap.port}", "tracker_port": tracker_port}
            connected = client.post("/api/v1/robot/connect", json=body, headers=auth)
            if connected.status_code != 200:
                raise SystemExit(f"connect: {connected.status_code} {connected.text}")
            result["idle"] = phase(client, auth, tap, seconds, presses)
            for count in clients:
                load = start_map_load(base, count)
                try:
                    result[f"{count} clients"] = phase(client, auth, tap, seconds, presses)
                finally:
                    result[f"{count} clients"]["map_answers"] = stop_map_load(load)
        finally:
            client.close()
            tap.listener.close()
            stop_processes(robot, service)
    return result


def table(result: dict) -> str:
    header = "heartbeat gaps at the robot: n  median    p99    max  |  e-stop http p50   p99   max  ack  [ms]"
    rows = [f"phase          {header}"]
    for name, entry in result.items():
        gaps, estop = entry["heartbeat_gaps"], entry["estop"]
        rows.append(
            f"{name:<14} {gaps['n']:>31} {gaps.get('median_ms', '-'):>7} {gaps.get('p99_ms', '-'):>6} "
            f"{gaps.get('max_ms', '-'):>6}  |  {estop.get('p50_ms', '-'):>15} {estop.get('p99_ms', '-'):>5} "
            f"{estop.get('max_ms', '-'):>5} {estop.get('acknowledged', 0):>3}/{estop['n']}"
        )
    return "\n".join(rows)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=20.0, help="each phase's length")
    parser.add_argument("--clients", type=int, nargs="*", default=[20, 50])
    parser.add_argument("--presses", type=int, default=20, help="e-stops per phase")
    parser.add_argument("--tree", type=Path, help="run this checkout's service (a base revision)")
    parser.add_argument("--json", action="store_true")
    options = parser.parse_args()
    result = measure(options.seconds, options.clients, options.presses, options.tree)
    print(json.dumps(result, indent=1) if options.json else table(result))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
