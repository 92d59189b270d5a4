"""The service under load: many clients reading and writing runs, idle and while a job computes.

Seeds ``--runs`` runs into a fresh SQLite store, starts the real ``parkour serve`` on it (its own
process, as in the lab), then for each client count runs two phases of ``--seconds`` each:
idle, and while a job computes (``--job mjtf``: 12,000 trials; ``--job basin``: a 200 x 200 grid,
1000 jumps), and with ``--export`` a third while one more client exports every run as CSV. Each
client loops: four filtered ``GET /api/v1/runs`` pages for every ``POST /api/v1/runs`` (4 jumps,
stored), each on its own keep-alive connection. The clients are coroutines in two processes of
their own speaking plain HTTP/1.1: they share this machine's cores with the service, so they must
cost little (an httpx client thread cost more CPU per request than the service).

Prints, per phase, throughput and p50/p95/max latency of the reads and the writes, and the
ratio of each phase's p95 to idle, and the CPU time the service's own process spent per request
answered (its worker processes not counted), and the whole machine's CPU per request (the read
workers that answer the run list's pages, the compute workers, the clients). ``--json`` for the
numbers alone.
Usage: PYTHONPATH=. python scripts/bench_load.py [--runs 20000] [--clients 20 50] [--seconds 20] [--job mjtf]
"""

from __future__ import annotations

import argparse
import asyncio
import concurrent.futures
import json
import multiprocessing
import os
import random
import shutil
import statistics
import tempfile
import threading
import time
import urllib.parse
from pathlib import Path

import httpx
from bench_store import QUERIES, seed  # scripts/ is on the path when this script runs

from tests.helpers import start_service

ROOT = Path(__file__).resolve().parents[1]
RUN = {"controls": [{"psi0_deg": 30, "zeta0": 0.9}], "start": {"xdot": -0.93, "ydot": -0.17}, "jumps": 4}
JOBS = {
    "mjtf": {"zeta0s": [0.86, 0.88, 0.9, 0.92], "trials": 3000, "cap": 1000, "seed": 1,
             "guess": {"xdot": -0.93, "ydot": -0.2}},
    "basin": {"kind": "basin", "controls": [{"psi0_deg": 30, "zeta0": 0.9}], "grid": 200, "jumps": 1000},
}  # fmt: skip
CLIENT_PROCESSES = 2


class Connection:
    """One keep-alive HTTP/1.1 connection speaking just what the bench sends and the service
    answers (Content-Length bodies): a few tens of microseconds of the bench's CPU per request,
    where an httpx client thread spent about 15 ms on this 2-core machine — more than the service
    it measured, which shares the cores (the lab's clients are on other machines)."""

    def __init__(self, host: str, port: int):
        self.host, self.port, self.reader, self.writer = host, port, None, None

    async def request(self, method: str, target: str, headers: dict[str, str], body: bytes = b"") -> int:
        if self.writer is None:
            self.reader, self.writer = await asyncio.open_connection(self.host, self.port)
        lines = [f"{method} {target} HTTP/1.1", f"Host: {self.host}:{self.port}", f"Content-Length: {len(body)}"]
        lines += [f"{name}: {value}" for name, value in headers.items()]
        self.writer.write(("\r\n".join(lines) + "\r\n\r\n").encode() + body)
        head = (await self.reader.readuntil(b"\r\n\r\n")).decode("latin-1").lower()
        status = int(head.split(" ", 2)[1])
        length = int(head.partition("content-length:")[2].split("\r\n", 1)[0] or 0)
        await self.reader.readexactly(length)
        if "connection: close" in head:  # a refusal closes the connection: open a new one next time
            self.writer.close()
            self.reader = self.writer = None
        return status


async def _client(host: str, port: int, token: str, deadline: float, seed_value: int) -> list[tuple[str, float, int]]:
    """One client: (kind, latency [s], status) of each request until ``deadline`` (monotonic)."""
    rng, out, connection = random.Random(seed_value), [], Connection(host, port)
    write_headers = {"Authorization": f"Bearer {token}", "Content-Type": "application/json"}
    body = json.dumps(RUN).encode()
    while time.monotonic() < deadline:
        write = rng.random() < 0.2
        started = time.perf_counter()
        if write:
            status = await connection.request("POST", "/api/v1/runs", write_headers, body)
        else:
            query = urllib.parse.urlencode(rng.choice(QUERIES) | {"limit": 50})
            status = await connection.request("GET", f"/api/v1/runs?{query}", {})
        out.append(("write" if write else "read", time.perf_counter() - started, status))
    return out


def _client_process(base: str, token: str, seconds: float, clients: int, first_seed: int) -> list:
    host, _, port = urllib.parse.urlsplit(base).netloc.partition(":")

    async def run() -> list:
        deadline = time.monotonic() + seconds
        tasks = [_client(host, int(port), token, deadline, first_seed + k) for k in range(clients)]
        return [request for client in await asyncio.gather(*tasks) for request in client]

    cpu_before = time.process_time()
    requests = asyncio.run(run())
    return requests, time.process_time() - cpu_before


def cpu_seconds(pid: int) -> float:
    """The CPU time (user + system) process ``pid`` has used so far, without its children (the
    compute workers): what the service's own process spends (Linux /proc)."""
    fields = Path(f"/proc/{pid}/stat").read_text().rpartition(")")[2].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def machine_cpu_seconds() -> float:
    """The CPU time every core of this machine has spent busy so far (Linux /proc/stat): the
    service, its read and compute workers, the clients and anything else running."""
    user, nice, system, _idle, _iowait, irq, softirq, steal = map(int, Path("/proc/stat").read_text().split()[1:9])
    return (user + nice + system + irq + softirq + steal) / os.sysconf("SC_CLK_TCK")


def phase(base: str, token: str, clients: int, seconds: float, service_pid: int | None = None) -> dict:
    cpu_before = cpu_seconds(service_pid) if service_pid else None
    machine_before = machine_cpu_seconds()
    per_process = [clients // CLIENT_PROCESSES + (k < clients % CLIENT_PROCESSES) for k in range(CLIENT_PROCESSES)]
    context = multiprocessing.get_context("spawn")
    with concurrent.futures.ProcessPoolExecutor(CLIENT_PROCESSES, mp_context=context) as pool:
        futures = [
            pool.submit(_client_process, base, token, seconds, n, 1000 * k) for k, n in enumerate(per_process) if n
        ]
        answers = [future.result() for future in futures]
    requests = [request for client_requests, _ in answers for request in client_requests]
    summary = {"requests": len(requests), "per_s": len(requests) / seconds, "errors": {}}
    # What the clients themselves cost (they share the cores with the service): keep it small.
    summary["client_cpu_ms_per_request"] = 1e3 * sum(cpu for _, cpu in answers) / max(len(requests), 1)
    if service_pid:  # the service's own CPU per request answered: what its event loop and GIL carry
        summary["service_cpu_ms_per_request"] = 1e3 * (cpu_seconds(service_pid) - cpu_before) / max(len(requests), 1)
    # Every process's, the read workers' (which answer the run list's pages) and the clients' too.
    summary["machine_cpu_ms_per_request"] = 1e3 * (machine_cpu_seconds() - machine_before) / max(len(requests), 1)
    for kind in ("read", "write"):
        times = sorted(latency for name, latency, status in requests if name == kind)
        if times:
            summary[kind] = {
                "count": len(times),
                "p50_ms": 1e3 * statistics.median(times),
                "p95_ms": 1e3 * times[int(0.95 * (len(times) - 1))],
                "max_ms": 1e3 * times[-1],
            }
    for _name, _latency, status in requests:
        if status >= 400:
            summary["errors"][str(status)] = summary["errors"].get(str(status), 0) + 1
    return summary


class Exporting:
    """While in its ``with``: one client downloading ``GET /api/v1/runs/export?format=csv`` (every
    run) back to back; :attr:`done` counts whole exports."""

    def __init__(self, base: str):
        self.base, self.done = base, 0
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._export, name="bench-export", daemon=True)

    def _export(self) -> None:
        with httpx.Client(base_url=self.base, timeout=120) as client:
            while not self._stop.is_set():
                with client.stream("GET", "/api/v1/runs/export", params={"format": "csv"}) as response:
                    for _ in response.iter_bytes():
                        if self._stop.is_set():
                            return
                self.done += 1

    def __enter__(self) -> Exporting:
        self._thread.start()
        return self

    def __exit__(self, *_) -> None:
        self._stop.set()
        self._thread.join(30)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=20_000)
    parser.add_argument("--clients", type=int, nargs="+", default=[20, 50])
    parser.add_argument("--seconds", type=float, default=20.0)
    parser.add_argument("--job", choices=sorted(JOBS), default="mjtf")
    parser.add_argument("--port", type=int, default=8765)
    parser.add_argument("--export", action="store_true", help="a third phase: one client exporting every run as CSV")
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args()
    data_dir = Path(tempfile.mkdtemp(prefix="parkourlab-load-"))
    seed(f"sqlite:///{data_dir / 'parkourlab.sqlite3'}", args.runs, random.Random(0))
    process = start_service(data_dir, args.port, "--no-view")
    base, token = f"http://127.0.0.1:{args.port}", (data_dir / "api_token").read_text().strip()
    auth = {"Authorization": f"Bearer {token}"}
    results = {"runs": args.runs, "job": args.job, "seconds": args.seconds, "phases": []}
    try:
        phase(base, token, 2, 3.0)  # warm: the workers' kernels, the database's pages
        for clients in args.clients:
            idle = phase(base, token, clients, args.seconds, process.pid)
            job = httpx.post(f"{base}/api/v1/jobs", json=JOBS[args.job], headers=auth).json()["id"]
            while httpx.get(f"{base}/api/v1/jobs/{job}").json()["state"] != "running":
                time.sleep(0.1)
            busy = phase(base, token, clients, args.seconds, process.pid)
            state = httpx.get(f"{base}/api/v1/jobs/{job}").json()
            httpx.post(f"{base}/api/v1/jobs/{job}/cancel", headers=auth)
            busy["job_state_at_end"], busy["job_completed"] = state["state"], state["completed"]
            results["phases"].append({"clients": clients, "idle": idle, "job": busy})
            if args.export:
                with Exporting(base) as exporting:
                    results["phases"][-1]["export"] = phase(base, token, clients, args.seconds, process.pid)
                results["phases"][-1]["export"]["exports_done"] = exporting.done
    finally:
        process.terminate()
        process.wait(30)
        shutil.rmtree(data_dir, ignore_errors=True)
    if args.json:
        print(json.dumps(results))
        return
    print(f"{args.runs} runs; phases of {args.seconds:g} s; job: {args.job}")
    header = ("clients", "phase", "req/s", "read p50", "p95", "max", "write p50", "p95", "max", "p95 x idle (r/w)",
              "cpu ms/req", "machine")  # fmt: skip
    widths = (7, 5, 7, 9, 7, 7, 10, 7, 7, 17, 11, 8)
    print(" ".join(f"{name:>{width}}" for name, width in zip(header, widths, strict=True)))
    for entry in results["phases"]:
        for name in ("idle", "job", "export"):
            if name not in entry:
                continue
            row = entry[name]
            ratio = "" if name == "idle" else " / ".join(
                f"{row[kind]['p95_ms'] / entry['idle'][kind]['p95_ms']:.1f}" for kind in ("read", "write"))  # fmt: skip
            read, write = row["read"], row["write"]
            print(
                f"{entry['clients']:>7} {name:>5} {row['per_s']:>7.0f} {read['p50_ms']:>9.1f} {read['p95_ms']:>7.1f} "
                f"{read['max_ms']:>7.0f} {write['p50_ms']:>10.1f} {write['p95_ms']:>7.1f} {write['max_ms']:>7.0f} "
                f"{ratio:>17} {row['service_cpu_ms_per_request']:>11.1f} {row['machine_cpu_ms_per_request']:>8.1f}  "
                f"{row['errors'] or ''}"
            )
        print(f"{'':>7} job: {entry['job']['job_state_at_end']}, {entry['job']['job_completed']} done during the phase")
        if "export" in entry:
            print(f"{'':>7} export: {entry['export']['exports_done']} whole CSV exports of every run during the phase")


if __name__ == "__main__":
    threading.current_thread().name = "bench-load"
    main()
