"""Latency of the run list at scale: seed N runs into a fresh SQLite store, then time filtered pages.

The issue's target: p95 under 50 ms for a filtered page at 100,000 runs. Requests go through
the real app (ASGI, in-process, so the network is not measured) on a real database file.

Usage: python scripts/bench_store.py [--runs 100000] [--requests 200] [--json]
"""

from __future__ import annotations

import argparse
import json
import random
import statistics
import tempfile
import time
from pathlib import Path

from fastapi.testclient import TestClient
from sqlalchemy import insert

from backend.api.app import create_app
from backend.settings import Settings
from backend.store.database import make_engine, migrate
from backend.store.models import Run, RunTag

TAGS = ["fig8", "fig11", "robot-a", "robot-b", "baseline", "noisy", "pid", "sweep"]
QUERIES = [
    {"zeta0_min": 0.85, "zeta0_max": 0.9},
    {"tag": "fig8"},
    {"kind": "sim", "failure_code": "slip"},
    {"psi0_min": 25, "psi0_max": 35, "zeta0_min": 0.9},
    {},
]


def run_row(run_id: int, psi0: float, zeta0: float, failure: str | None, jumps_completed: int, rng) -> dict:
    """A stored run's row as the benches seed it: 20 jumps of one leg pair on the paper's model
    (its ``kind``, ``duration_s`` and ``results`` are each bench's)."""
    return {
        "id": run_id,
        "status": "done",
        "code_version": "bench",
        "model": {"alpha": 77.6, "d_hat": 2.42, "c_zeta": 0.31, "c_psi": 0.31, "mu": 2.0},
        "controls": [[psi0, zeta0]],
        "start_state": [-0.93, -0.17],
        "jumps": 20,
        "alpha": 77.6,
        "psi0_deg": psi0,
        "zeta0": zeta0,
        "failure_code": failure,
        "jumps_completed": jumps_completed,
        "climb": rng.uniform(-1, 8),
    }


def seed(url: str, count: int, rng: random.Random) -> None:
    engine = make_engine(url)
    migrate(engine)
    failures = [None, None, None, "slip", "no_flight", "collapse"]
    with engine.begin() as connection:
        for start in range(0, count, 10_000):
            rows, tags = [], []
            for run_id in range(start + 1, min(start + 10_000, count) + 1):
                zeta0, psi0 = rng.uniform(0.8, 0.98), rng.uniform(15, 45)
                failure = rng.choice(failures)
                jumps_completed = 20 if failure is None else rng.randrange(20)
                row = run_row(run_id, psi0, zeta0, failure, jumps_completed, rng)
                row |= {"kind": rng.choice(["sim", "sim", "sim", "robot"]), "duration_s": rng.uniform(0.001, 0.5)}
                rows.append(row | {"results": {"states": [[-0.93, -0.17]] * 21, "rises": [0.33] * 20, "failure": None}})
                tags += [{"run_id": run_id, "tag": tag} for tag in rng.sample(TAGS, 2)]
            connection.execute(insert(Run), rows)
            connection.execute(insert(RunTag), tags)
    engine.dispose()


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=100_000)
    parser.add_argument("--requests", type=int, default=200)
    parser.add_argument("--json", action="store_true")
    options = parser.parse_args()
    rng = random.Random(0)
    with tempfile.TemporaryDirectory() as directory:
        settings = Settings.from_environment(Path(directory))
        began = time.perf_counter()
        seed(settings.database_url, options.runs, rng)
        seeded = time.perf_counter() - began
        # base_url: the service answers to its allow-listed Host names (TestClient says "testserver").
        with TestClient(create_app(settings, run_jobs=False), base_url="http://localhost") as client:
            client.get("/api/v1/runs", params={"limit": 50})  # warm up
            latencies = []
            for request in range(options.requests):
                params = QUERIES[request % len(QUERIES)] | {"limit": 50}
                start = time.perf_counter()
                response = client.get("/api/v1/runs", params=params)
                latencies.append((time.perf_counter() - start) * 1000)
                assert response.status_code == 200 and response.json()["items"], params
    latencies.sort()
    result = {
        "runs": options.runs,
        "requests": options.requests,
        "seed_seconds": seeded,
        "p50_ms": statistics.median(latencies),
        "p95_ms": latencies[int(0.95 * (len(latencies) - 1))],
        "max_ms": latencies[-1],
    }
    if options.json:
        print(json.dumps(result))
    else:
        print(
            f"{result['runs']:,} runs (seeded in {seeded:.1f} s), {result['requests']} filtered pages of 50: "
            f"p50 {result['p50_ms']:.1f} ms, p95 {result['p95_ms']:.1f} ms, max {result['max_ms']:.1f} ms"
        )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
