"""Heartbeat gaps as the robot sees them, and the e-stop's round trip, idle and under load.

docs/protocol.md §3: the PC sends HEARTBEAT at least every 0.2 s; the robot disarms after 1 s
without a frame. This measures what arrives at the robot: the service (``parkour serve --no-view``,
SQLite in a temporary directory) connects to ``socket://`` on a tap in this process, which forwards
every byte to and from the virtual robot (``parkour robot-sim``, its own process, real time, its
default noise) and timestamps each frame either way, decoded with the link's own frame and message
codecs: the PC's Transmit Requests (every command and heartbeat, by seq) and the robot's Receive
Packets (its ACKs, by the seq they acknowledge).

Phases (``--phases``, comma-separated, run in order; each a ``+``-joined set of conditions):

- ``idle``: nothing but the link.
- ``clients`` / ``clients=N``: N clients POSTing ``/api/v1/sim/map`` back to back from another
  process; bare ``clients`` is one phase per count in ``--clients`` (default 20 and 50).
- ``closed``: a live closed-loop run on the virtual robot during the whole phase: POST
  ``/api/v1/robot/runs`` with both legs at psi0 35°, zeta0 0.9, 300 jumps, ``max_seconds`` the
  phase's length + 30 s, ``closed_loop`` {target 0.4 m, LQR}; a run that ends before the phase
  does (a fall, an e-stop press, ...) is started again (after a RESET if the latch holds; 0.5 s
  later if it ended in an error), and the phase reports each run's end reason, touchdowns and
  seconds, and the POST's round trip (``start_http``). The run still going at the phase's end is
  stopped (``/robot/runs/stop``: its reason "stopped"). Before the first phase, a warm-up run
  (to its second touchdown, then stopped; ``setup.warm_up_run``) takes the service's first-run
  costs out of the phases.
- ``burners`` / ``burners=N``: N CPU-busy processes (pure-Python spin loops) started for the phase
  and killed after it; bare ``burners``: ``--burners`` if given, else twice the machine's CPUs.
- ``issue``: the issue's condition, ``closed+clients=20+burners`` (on a 2-core machine: a closed
  loop, 20 clients and 4 burners). Its target: heartbeat gaps p99 <= 150 ms and max <= 300 ms,
  e-stop acknowledged <= 150 ms max.

Default: ``idle,clients,closed,issue``. ``--closed-loop`` adds ``closed`` to every phase and
``--burners N`` adds N burners to every phase that does not name its own count. Loads start
before a phase's measurement begins and stop after it ends.

Per phase:

- ``heartbeat_gaps``: gaps between consecutive heartbeats the PC wrote, at the tap (median, p99 by
  nearest rank, max, and how many exceed 150, 300 and 350 ms). An ESTOP counts as the heartbeat it
  replaces, as during a press; ``heartbeat_only_gaps`` leaves them out; ``heartbeat_gaps_in_runs``
  (closed phases) keeps only the gaps inside one live run (from its POST's answer to the poll
  that saw it end).
- ``estop``: ``--presses`` e-stop presses (no token), each followed by a RESET (the token's call).
  Phases without a closed loop press back to back every 0.5 s from the phase's start; closed
  phases spread the presses evenly over the phase, at most one per 5 s (so the phase is mostly a
  run under way, not its start), each once a run has been going for at least 1 s (the press ends
  that run; the next one starts after the RESET). ``http``: the POST's round trip;
  ``service_latency``: the ``latency_ms`` the service answered; ``acknowledged``: how many
  said so; ``at_tap``: from the first ESTOP frame the PC wrote (its seq) to the robot's ACK of that
  seq as the tap saw it, for every ESTOP seq written in the phase (``unacknowledged``: none seen).
- ``commands``: SET_LEG frames the PC wrote in the phase, how long until the robot's ACK of each
  (p50, p99, max), ``late`` (> 0.5 s, or never acknowledged) and ``unacknowledged``; ``resent``:
  seqs written more than once on one connection other than ESTOP (which §3 repeats), and the
  extra writes.
- ``worst_gaps``: the 5 longest of those gaps, when in the phase each began, and what the bench
  did meanwhile (run asked/answered/seen ended, e-stop, reset; ms from the gap's start).
- ``loadavg``: the 1/5/15-min load averages at the phase's start and end (``os.getloadavg``:
  other work on the machine counts too; the 1-min figure lags a phase's own load by about a
  minute; ``--lead-in S`` runs a loaded phase's clients and burners S seconds before measuring).
- ``runs`` (closed phases): each run's end reason, touchdowns, commands and seconds; start failures.

The tap is Python in this process: its timestamps carry its own scheduling delay under load, as
the virtual robot's (also Python) would.

Usage, from the checkout's root:

    PYTHONPATH=. python scripts/bench_heartbeat.py [--seconds 20] [--phases idle,clients,closed,issue]
        [--clients 20 50] [--burners N] [--closed-loop] [--presses 20] [--lead-in 0] [--tree PATH] [--json]

``--tree`` runs another checkout's service (e.g. ``git archive`` or a ``git worktree`` of the
base revision) with this venv, for a side-by-side before/after; the virtual robot, the tap and the
loads are this checkout's either way.
"""

from __future__ import annotations

import argparse
import itertools
import json
import math
import os
import socket
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from collections import Counter
from dataclasses import dataclass
from pathlib import Path

import httpx

from backend.robot.messages import Ack, Command, Kind, SetLeg, decode
from backend.robot.xbee import RX_PACKET, TX_REQUEST, FrameError, FrameParser, parse_rx_packet, parse_tx_request
from tests.helpers import free_port, start_map_load, start_robot_sim, start_service, stop_map_load, stop_processes

TIMEOUT_S = 60.0  # [s] any one request: a bound, not a measurement
PRESS_EVERY_S = 0.5  # [s] between e-stop presses within a phase without a closed loop
CLOSED_PRESS_EVERY_S = 5.0  # [s] a closed phase presses at most this often (mostly a run under way, not its start)
RUN_SETTLE_S = 1.0  # [s] a closed phase presses only once its run has gone this long
POLL_S = 0.2  # [s] between polls of the robot's status in a closed phase
START_RETRY_S = 0.5  # [s] before starting a run again after a refusal
RUN_MARGIN_S = 30.0  # [s] a run's max_seconds beyond its phase's length
LATE_ACK_S = 0.5  # [s] a SET_LEG acknowledged later than this is late
GAP_BOUNDS_MS = (150, 300, 350)
ACK_GRACE_S = 1.0  # [s] after a phase, for the ACKs of its last frames to arrive
ISSUE = "closed+clients=20+burners"
BURN = "while True: pass"


def closed_loop_body(seconds: float) -> dict:
    """The live run a closed phase keeps going (no ``tracker_timeout_ms``: the service's default)."""
    return {
        "controls": [{"psi0_deg": 35, "zeta0": 0.9}] * 2,
        "jumps": 300,
        "max_seconds": min(3600.0, seconds + RUN_MARGIN_S),
        "closed_loop": {"target_m": 0.4, "controller": "lqr"},
    }


class Tap:
    """A TCP relay between the service's link and the virtual robot that timestamps the messages
    either way: every one the PC writes (kind, seq) and every ACK the robot sends (the seq it acks)."""

    def __init__(self, robot_port: int):
        self.robot_port = robot_port
        self.listener = socket.create_server(("127.0.0.1", 0))
        self.port = self.listener.getsockname()[1]
        self.writes: list[tuple[float, int, Kind, int]] = []  # (monotonic time, connection, kind, seq)
        self.acks: list[tuple[float, int, int, int]] = []  # (monotonic time, connection, acked seq, result)
        self._connections = itertools.count(1)
        self._lock = threading.Lock()
        threading.Thread(target=self._accept, name="tap", daemon=True).start()

    def snapshot(self) -> tuple[list, list]:
        with self._lock:
            return list(self.writes), list(self.acks)

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
            connection = next(self._connections)
            threading.Thread(target=self._pump, args=(pc, robot, True, connection), daemon=True).start()
            threading.Thread(target=self._pump, args=(robot, pc, False, connection), daemon=True).start()

    def _pump(self, source: socket.socket, sink: socket.socket, from_pc: bool, connection: int) -> None:
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
            for data in parser.feed(chunk):
                (self._note_pc if from_pc else self._note_robot)(arrived, connection, data)
            try:
                sink.sendall(chunk)
            except OSError:
                return

    def _note_pc(self, arrived: float, connection: int, data: bytes) -> None:
        if data[0] != TX_REQUEST:
            return
        try:
            message = decode(parse_tx_request(data)[2])
        except (FrameError, ValueError):
            return
        if isinstance(message, SetLeg):
            kind = Kind.SET_LEG
        elif isinstance(message, Command):
            kind = message.kind
        else:
            return
        with self._lock:
            self.writes.append((arrived, connection, kind, message.seq))

    def _note_robot(self, arrived: float, connection: int, data: bytes) -> None:
        if data[0] != RX_PACKET:  # the radio's Transmit Statuses
            return
        try:
            message = decode(parse_rx_packet(data).payload)
        except (FrameError, ValueError):
            return
        if isinstance(message, Ack):
            with self._lock:
                self.acks.append((arrived, connection, message.acked, int(message.result)))


# Figures ---------------------------------------------------------------------------------------


def nearest_rank(ordered: list[float], fraction: float) -> float:
    """The ``fraction`` percentile of sorted values by nearest rank (never below the median of few)."""
    return ordered[max(0, math.ceil(fraction * len(ordered)) - 1)]


def spread_ms(values: list[float]) -> dict:
    """n, median, p99 (nearest rank) and max of values in ms."""
    values = sorted(values)
    if not values:
        return {"n": 0}
    return {
        "n": len(values),
        "p50_ms": round(statistics.median(values), 1),
        "p99_ms": round(nearest_rank(values, 0.99), 1),
        "max_ms": round(values[-1], 1),
    }


def gaps_ms(times: list[float], runs: list[tuple[float, float]] | None = None) -> dict:
    """Gaps between consecutive ``times`` [s] in ms; ``runs``: only gaps within one of these intervals."""
    gaps = [
        (b - a) * 1000
        for a, b in itertools.pairwise(times)
        if runs is None or any(start <= a and b <= end for start, end in runs)
    ]
    figures = spread_ms(gaps)
    if gaps:
        figures.update({f"over_{bound}": sum(gap > bound for gap in gaps) for bound in GAP_BOUNDS_MS})
    return figures


def heartbeat_figures(writes: list, start: float, end: float, runs: list[tuple[float, float]] | None) -> dict:
    def times(kinds: set[Kind]) -> list[float]:
        return [t for t, _connection, kind, _seq in writes if start <= t < end and kind in kinds]

    slots = times({Kind.HEARTBEAT, Kind.ESTOP})  # the robot's watchdog slots: a heartbeat or the ESTOP in its place
    figures = {"heartbeat_gaps": gaps_ms(slots), "heartbeat_only_gaps": gaps_ms(times({Kind.HEARTBEAT}))}
    if runs is not None:
        figures["heartbeat_gaps_in_runs"] = gaps_ms(slots, runs)
    return figures


def worst_gaps(writes: list, start: float, end: float, events: list[tuple[float, str]], count: int = 5) -> list[dict]:
    """The ``count`` longest heartbeat gaps (an ESTOP counting as one), when in the phase they began
    [s], and what the bench did or saw from 0.5 s before each to its end (ms from its start)."""
    slots = [t for t, _connection, kind, _seq in writes if start <= t < end and kind in (Kind.HEARTBEAT, Kind.ESTOP)]
    gaps = sorted(itertools.pairwise(slots), key=lambda gap: gap[0] - gap[1])[:count]
    return [
        {
            "ms": round((b - a) * 1000, 1),
            "at_s": round(a - start, 2),
            "events": [f"{what} {(t - a) * 1000:+.0f} ms" for t, what in events if a - 0.5 <= t <= b],
        }
        for a, b in gaps
    ]


def link_figures(writes: list, acks: list, start: float, end: float) -> dict:
    """The e-stop's acknowledgement at the tap, SET_LEG acknowledgements and resent commands for
    the frames the PC wrote in [start, end)."""
    first: dict[tuple[int, int], tuple[float, Kind]] = {}  # (connection, seq) -> first write
    written: Counter = Counter()
    for t, connection, kind, seq in writes:
        key = (connection, seq)
        if key in first and first[key][1] != kind:  # the seq came round again (65536 frames on): a new one
            del first[key]
            written[key] = 0
        first.setdefault(key, (t, kind))
        written[key] += 1
    acked: dict[tuple[int, int], list[float]] = {}
    for t, connection, seq, _result in acks:
        acked.setdefault((connection, seq), []).append(t)

    def ack_after(key: tuple[int, int], t0: float) -> float | None:
        return next((t for t in acked.get(key, ()) if t >= t0), None)

    estop, estop_missing, set_leg, set_leg_missing, resent, extra = [], 0, [], 0, 0, 0
    for key, (t0, kind) in first.items():
        if not start <= t0 < end:
            continue
        t1 = ack_after(key, t0)
        if kind == Kind.ESTOP:
            if t1 is None:
                estop_missing += 1
            else:
                estop.append((t1 - t0) * 1000)
            continue
        if written[key] > 1:
            resent += 1
            extra += written[key] - 1
        if kind == Kind.SET_LEG:
            if t1 is None:
                set_leg_missing += 1
            else:
                set_leg.append((t1 - t0) * 1000)
    return {
        "estop_at_tap": {**spread_ms(estop), "unacknowledged": estop_missing},
        "commands": {
            "set_leg_ack": spread_ms(set_leg),
            "set_leg_late": sum(ms > LATE_ACK_S * 1000 for ms in set_leg) + set_leg_missing,
            "set_leg_unacknowledged": set_leg_missing,
            "resent_seqs": resent,
            "resent_writes": extra,
        },
    }


# Phases ----------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Phase:
    clients: int = 0
    burners: int = 0
    closed: bool = False
    label: str = ""  # the name it was asked by, when that says more than its conditions (issue)

    @property
    def name(self) -> str:
        parts = (["closed"] if self.closed else []) + [f"{self.clients} clients"] * bool(self.clients)
        parts += [f"{self.burners} burners"] * bool(self.burners)
        name = "+".join(parts) or "idle"
        return f"{self.label} ({name})" if self.label else name


def parse_phases(text: str, client_counts: list[int], burners: int | None, closed_loop: bool) -> list[Phase]:
    """``--phases`` (see the module's doc) into phases, with ``--burners`` and ``--closed-loop`` applied."""
    default_burners = burners if burners else 2 * (os.cpu_count() or 1)
    phases = []
    for item in filter(None, (part.strip() for part in text.split(","))):
        label = "issue" if item == "issue" else ""
        spec = ISSUE if item == "issue" else item
        clients: list[int] = [0]
        own_burners, closed = None, closed_loop
        for condition in spec.split("+"):
            word, _, count = condition.strip().partition("=")
            if count and not count.isdigit():
                raise SystemExit(f"--phases: {condition!r}: a count is a whole number")
            if word == "idle" and not count:
                continue
            if word == "closed" and not count:
                closed = True
            elif word == "clients":
                clients = [int(count)] if count else client_counts
            elif word == "burners":
                own_burners = int(count) if count else default_burners
            else:
                raise SystemExit(f"--phases: unknown condition {condition!r} (idle, closed, clients[=N], burners[=N])")
        for count in clients:
            phases.append(Phase(count, own_burners if own_burners is not None else (burners or 0), closed, label))
    return phases


def start_burners(count: int) -> list[subprocess.Popen]:
    return [subprocess.Popen([sys.executable, "-c", BURN]) for _ in range(count)]


class Bench:
    """The service, the virtual robot and the tap between them, connected; one phase at a time."""

    def __init__(self, data: Path, tree: Path | None, presses: int):
        self.presses = presses
        port, self.tracker_port, robot_port = free_port(), free_port(socket.SOCK_DGRAM), free_port()
        self.service = start_service(data, port, "--no-view", tree=tree)
        self.robot = start_robot_sim(robot_port, self.tracker_port)
        self.tap = Tap(robot_port)
        self.base = f"http://127.0.0.1:{port}"
        self.client = httpx.Client(base_url=self.base, timeout=TIMEOUT_S)
        self.auth = {"Authorization": f"Bearer {(data / 'api_token').read_text().strip()}"}
        # (monotonic time, what this bench did or saw): the worst gaps' context
        self.events: list[tuple[float, str]] = []

    def note(self, what: str) -> None:
        self.events.append((time.monotonic(), what))

    def connect(self) -> None:
        body = {"url": f"socket://127.0.0.1:{self.tap.port}", "tracker_port": self.tracker_port}
        connected = self.client.post("/api/v1/robot/connect", json=body, headers=self.auth)
        if connected.status_code != 200:
            raise SystemExit(f"connect: {connected.status_code} {connected.text}")

    def close(self) -> None:
        self.client.close()
        self.tap.listener.close()
        stop_processes(self.robot, self.service)

    def run_phase(self, phase: Phase, seconds: float, lead_in: float) -> dict:
        loadavg_start = os.getloadavg()
        burners = start_burners(phase.burners)
        load = None
        entry: dict = {"clients": phase.clients, "burners": phase.burners, "closed_loop": phase.closed}
        try:
            if phase.clients:
                load = start_map_load(self.base, phase.clients)
            if phase.clients or phase.burners:
                time.sleep(lead_in)
            start = time.monotonic()
            presses = Presses()
            runs = RunKeeper(self, seconds) if phase.closed else None
            if runs is None:
                self.press_back_to_back(presses, start + seconds)
            else:
                runs.keep(presses, start, start + seconds, self.presses)
            time.sleep(max(0.0, start + seconds - time.monotonic()))
            end = time.monotonic()
            entry["loadavg"] = {
                "start": [round(x, 2) for x in loadavg_start],
                "end": [round(x, 2) for x in os.getloadavg()],
            }
            if runs is not None:
                runs.finish()
        finally:
            stop_processes(*burners, timeout=5)
            if load is not None:
                entry["map_answers"] = stop_map_load(load)
        time.sleep(max(0.0, end + ACK_GRACE_S - time.monotonic()))
        writes, acks = self.tap.snapshot()
        entry.update(heartbeat_figures(writes, start, end, None if runs is None else runs.intervals()))
        entry["worst_gaps"] = worst_gaps(writes, start, end, self.events)
        figures = link_figures(writes, acks, start, end)
        entry["estop"] = {**presses.figures(), "at_tap": figures["estop_at_tap"]}
        entry["commands"] = figures["commands"]
        if runs is not None:
            entry["runs"] = runs.figures()
        return entry

    def warm_up(self) -> dict:
        """One closed-loop run to its second touchdown (at most 20 s), then stopped: the service's first
        run compiles and designs what later ones reuse, which is no part of any phase's figures."""
        keeper = RunKeeper(self, 20.0)
        deadline = time.monotonic() + 30.0
        while not keeper.runs and time.monotonic() < deadline:
            status = keeper.look()
            if keeper.current is None:
                keeper.start(status)
            elif (status["run"] or {}).get("touchdowns", 0) >= 2:
                break
            time.sleep(POLL_S)
        keeper.finish()
        return {key: keeper.figures()[key] for key in ("runs", "start_http")} | (
            {"start_failures": dict(keeper.start_failures)} if keeper.start_failures else {}
        )

    def press(self, presses: Presses) -> None:
        self.note("e-stop asked")
        started = time.perf_counter()
        answer = self.client.post("/api/v1/robot/estop")
        presses.note((time.perf_counter() - started) * 1000, answer)
        self.note("e-stop answered")

    def reset(self) -> httpx.Response:
        self.note("reset asked")
        answer = self.client.post("/api/v1/robot/reset", headers=self.auth)
        self.note(f"reset answered {answer.status_code}")
        return answer

    def press_back_to_back(self, presses: Presses, end: float) -> None:
        for _ in range(self.presses):
            if time.monotonic() >= end:
                break
            started = time.perf_counter()
            self.press(presses)
            self.reset()
            time.sleep(max(0.0, PRESS_EVERY_S - (time.perf_counter() - started)))


class Presses:
    """The e-stop presses of a phase as the HTTP client saw them."""

    def __init__(self):
        self.http_ms: list[float] = []
        self.service_ms: list[float] = []
        self.acknowledged = 0
        self.failures: Counter = Counter()

    def note(self, http_ms: float, answer: httpx.Response) -> None:
        self.http_ms.append(http_ms)
        if answer.status_code != 200:
            self.failures[f"{answer.status_code}"] += 1
            return
        body = answer.json()
        self.acknowledged += bool(body["acknowledged"])
        self.service_ms.append(float(body["latency_ms"]))
        if not body["acknowledged"]:
            self.failures[body.get("reason") or "not acknowledged"] += 1

    def figures(self) -> dict:
        figures = {"http": spread_ms(self.http_ms), "service_latency": spread_ms(self.service_ms),
                   "presses": len(self.http_ms), "acknowledged": self.acknowledged}  # fmt: skip
        if self.failures:
            figures["not_acknowledged"] = dict(self.failures)
        return figures


class RunKeeper:
    """A closed phase: keeps a live closed-loop run going, presses the e-stop during runs."""

    def __init__(self, bench: Bench, seconds: float):
        self.bench, self.body = bench, closed_loop_body(seconds)
        self.runs: list[dict] = []  # ended: id, end_reason, touchdowns, commands, seconds
        self.spans: list[tuple[float, float]] = []  # (start, end) monotonic of each ended run
        self.current: dict | None = None  # id, started (monotonic)
        self.start_failures: Counter = Counter()
        self.resets_refused = 0
        self.start_ms: list[float] = []  # each accepted POST /robot/runs's round trip

    def status(self) -> dict:
        return self.bench.client.get("/api/v1/robot").json()

    def look(self) -> dict:
        """The robot's status; notes the current run's end."""
        status = self.status()
        run = status.get("run")
        if self.current is not None and (run is None or run["id"] != self.current["id"] or not run["active"]):
            ended = time.monotonic()
            mine = run is not None and run["id"] == self.current["id"]
            self.runs.append({
                "id": self.current["id"],
                "end_reason": (run["end_reason"] or "?") if mine else "unknown (another run replaced it)",
                "touchdowns": run["touchdowns"] if mine else None,
                "commands": run["commands"] if mine else None,
                "disarm": run.get("disarm") if mine else None,
                "robot_faults": run.get("robot_faults") if mine else None,
                "seconds": round(ended - self.current["started"], 2),
            })  # fmt: skip
            self.spans.append((self.current["started"], ended))
            self.bench.note(f"run {self.current['id']} seen ended")
            self.current = None
        return status

    def start(self, status: dict) -> None:
        if self.runs and self.runs[-1]["end_reason"].startswith("error"):
            time.sleep(START_RETRY_S)  # a service that cannot run one: no spinning
        if status["estop"]["latched"] and self.bench.reset().status_code != 200:
            self.resets_refused += 1
            time.sleep(START_RETRY_S)
            return
        asked = time.perf_counter()
        self.bench.note("run asked")
        answer = self.bench.client.post("/api/v1/robot/runs", json=self.body, headers=self.bench.auth)
        self.bench.note(f"run answered {answer.status_code}")
        if answer.status_code == 202:
            self.start_ms.append((time.perf_counter() - asked) * 1000)
            self.current = {"id": answer.json()["run"]["id"], "started": time.monotonic()}
            return
        try:
            detail = answer.json().get("detail")
        except ValueError:
            detail = answer.text[:200]
        self.start_failures[f"{answer.status_code}: {str(detail)[:200]}"] += 1
        time.sleep(START_RETRY_S)

    def keep(self, presses: Presses, start: float, end: float, count: int) -> None:
        count = min(count, int((end - start) / CLOSED_PRESS_EVERY_S))
        due = [start + (i + 0.5) * (end - start) / count for i in range(count)]
        while (now := time.monotonic()) < end:
            status = self.look()
            if self.current is None:
                self.start(status)
                continue
            if due and now >= due[0] and now - self.current["started"] >= RUN_SETTLE_S:
                due.pop(0)
                self.bench.press(presses)
                continue
            time.sleep(POLL_S)

    def finish(self) -> None:
        """Stop the run still going, note its end, and leave the robot reset."""
        status = self.look()
        if self.current is not None:
            self.bench.note("run stop asked")
            self.bench.client.post("/api/v1/robot/runs/stop", headers=self.bench.auth)
            deadline = time.monotonic() + 30
            while self.current is not None and time.monotonic() < deadline:
                status = self.look()
                time.sleep(POLL_S / 2)
        if status["estop"]["latched"]:
            self.bench.reset()

    def intervals(self) -> list[tuple[float, float]]:
        return list(self.spans)

    def figures(self) -> dict:
        reasons = Counter(run["end_reason"].split(":")[0] for run in self.runs)
        figures = {
            "started": len(self.runs),
            "end_reasons": dict(reasons),
            "touchdowns": sum(run["touchdowns"] or 0 for run in self.runs),
            "start_http": spread_ms(self.start_ms),
            "runs": self.runs,
        }
        if self.start_failures:
            figures["start_failures"] = dict(self.start_failures)
        if self.resets_refused:
            figures["resets_refused"] = self.resets_refused
        return figures


def measure(seconds: float, phases: list[Phase], presses: int, tree: Path | None, lead_in: float = 0.0) -> dict:
    result: dict = {
        "setup": {
            "cpus": os.cpu_count(),
            "loadavg_before": [round(x, 2) for x in os.getloadavg()],
            "seconds": seconds,
            "presses": presses,
            "lead_in_s": lead_in,
            "tree": str(tree) if tree else None,
            "closed_loop_run": closed_loop_body(seconds),
        },
        "phases": {},
    }
    with tempfile.TemporaryDirectory(prefix="bench-heartbeat-") as data:
        bench = Bench(Path(data), tree, presses)
        try:
            bench.connect()
            if any(phase.closed for phase in phases):
                result["setup"]["warm_up_run"] = bench.warm_up()
            for phase in phases:
                name = phase.name
                for n in itertools.count(2):
                    if name not in result["phases"]:
                        break
                    name = f"{phase.name} #{n}"
                result["phases"][name] = bench.run_phase(phase, seconds, lead_in)
        finally:
            bench.close()
    return result


# Output ----------------------------------------------------------------------------------------


def table(result: dict) -> str:
    def cell(figures: dict, key: str, width: int) -> str:
        return f"{figures.get(key, '-'):>{width}}"

    setup = result["setup"]
    rows = [
        f"{setup['cpus']} CPUs, load before {setup['loadavg_before']}, {setup['seconds']:g} s a phase"
        + (f", service from {setup['tree']}" if setup["tree"] else ""),
        "",
        f"{'phase':<36} {'load1':>5} | heartbeat gaps at the robot [ms]: {'n':>5} {'p50':>6} {'p99':>6} {'max':>6}"
        f" {'>150':>4} {'>300':>4} {'>350':>4} | in runs: {'p99':>6} {'max':>6}",
    ]
    for name, entry in result["phases"].items():
        gaps, in_runs = entry["heartbeat_gaps"], entry.get("heartbeat_gaps_in_runs", {})
        rows.append(
            f"{name:<36} {entry['loadavg']['end'][0]:>5} | {'':>33} {gaps['n']:>5} {cell(gaps, 'p50_ms', 6)}"
            f" {cell(gaps, 'p99_ms', 6)} {cell(gaps, 'max_ms', 6)} {cell(gaps, 'over_150', 4)}"
            f" {cell(gaps, 'over_300', 4)} {cell(gaps, 'over_350', 4)} | {'':>8} {cell(in_runs, 'p99_ms', 6)}"
            f" {cell(in_runs, 'max_ms', 6)}"
        )
    rows += [
        "",
        f"{'phase':<36} | e-stop http [ms]: {'p50':>6} {'p99':>6} {'max':>6} {'ack':>7} | at tap: {'n':>3}"
        f" {'p50':>6} {'p99':>6} {'max':>6} {'miss':>4} | SET_LEG: {'n':>5} {'max':>7} {'late':>4} | resent",
    ]
    for name, entry in result["phases"].items():
        estop, commands = entry["estop"], entry["commands"]
        http, tap, legs = estop["http"], estop["at_tap"], commands["set_leg_ack"]
        rows.append(
            f"{name:<36} | {'':>16} {cell(http, 'p50_ms', 6)} {cell(http, 'p99_ms', 6)} {cell(http, 'max_ms', 6)}"
            f" {estop['acknowledged']:>3}/{estop['presses']:<3} | {'':>7} {tap['n']:>3} {cell(tap, 'p50_ms', 6)}"
            f" {cell(tap, 'p99_ms', 6)} {cell(tap, 'max_ms', 6)} {tap['unacknowledged']:>4} | {'':>8} {legs['n']:>5}"
            f" {cell(legs, 'max_ms', 7)} {commands['set_leg_late']:>4} | {commands['resent_seqs']}"
        )
    for name, entry in result["phases"].items():
        runs = entry.get("runs")
        extra = [f"map answers {entry['map_answers']}"] if "map_answers" in entry else []
        if "not_acknowledged" in entry["estop"]:
            extra.append(f"e-stops not acknowledged: {entry['estop']['not_acknowledged']}")
        worst = [gap for gap in entry["worst_gaps"] if gap["ms"] > GAP_BOUNDS_MS[0]]
        extra += [f"gap {gap['ms']} ms at {gap['at_s']} s: {', '.join(gap['events']) or '-'}" for gap in worst]
        if runs is not None:
            extra.append(f"{runs['started']} runs, {runs['touchdowns']} touchdowns, ended: {runs['end_reasons']};"
                         f" POST /robot/runs {runs['start_http']}")  # fmt: skip
            extra += [f"start refused: {why} x{n}" for why, n in runs.get("start_failures", {}).items()]
            others = Counter(
                run["end_reason"]
                for run in runs["runs"]
                if run["end_reason"] != "stopped" and not run["end_reason"].startswith("e-stop")
            )
            extra += [f"ended {n}x: {why}" for why, n in others.items()]
        if extra:
            rows += ["", f"{name}: load {entry['loadavg']['start']} -> {entry['loadavg']['end']}"]
            rows += [f"  {line}" for line in extra]
    return "\n".join(rows)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=20.0, help="each phase's length")
    parser.add_argument("--phases", default="idle,clients,closed,issue",
                        help="comma-separated phases, each conditions joined by +: idle, closed, clients[=N], "
                        "burners[=N], issue (= closed+clients=20+burners)")  # fmt: skip
    parser.add_argument("--clients", type=int, nargs="*", default=[20, 50], help="the counts of a bare 'clients'")
    parser.add_argument("--burners", type=int, default=0,
                        help="CPU-busy processes in every phase that names no count (bare 'burners': this, "
                        "or twice the CPUs if 0)")  # fmt: skip
    parser.add_argument("--closed-loop", action="store_true", help="a closed-loop run in every phase")
    parser.add_argument("--presses", type=int, default=20, help="e-stops per phase (closed: at most one per 5 s)")
    parser.add_argument(
        "--lead-in",
        type=float,
        default=0.0,
        help="[s] a loaded phase's clients and burners run this long before it is measured",
    )
    parser.add_argument("--tree", type=Path, help="run this checkout's service (a base revision)")
    parser.add_argument("--json", action="store_true")
    options = parser.parse_args()
    phases = parse_phases(options.phases, options.clients, options.burners, options.closed_loop)
    if not phases:
        raise SystemExit("--phases: no phase")
    result = measure(options.seconds, phases, options.presses, options.tree, options.lead_in)
    print(json.dumps(result, indent=1) if options.json else table(result))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
