"""Run exports: rows per second of ``GET /api/v1/runs/export`` as CSV and as JSON.

Seeds ``--runs`` runs into a fresh SQLite store (as scripts/bench_store.py does) and streams the
whole export through the service's functions — what the route streams — timing each format,
best of ``--repeats``. Run it on two checkouts to compare them. ``--json`` for the numbers alone.
"""

from __future__ import annotations

import argparse
import json
import random
import tempfile
import time
from pathlib import Path

from bench_store import seed  # scripts/ is on the path when this script runs

from backend.repositories.runs import RunFilter
from backend.services import exports
from backend.store.database import make_engine, session_factory


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=20_000)
    parser.add_argument("--repeats", type=int, default=3, help="best of this many exports per format (noisy machines)")
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args()
    url = f"sqlite:///{Path(tempfile.mkdtemp()) / 'parkourlab.sqlite3'}"
    seed(url, args.runs, random.Random(0))
    sessions = session_factory(make_engine(url))
    result = {"runs": args.runs}
    for name in ("csv", "json"):
        times = []
        for _ in range(args.repeats):
            started = time.perf_counter()
            size = sum(len(chunk) for chunk in exports.export(sessions, RunFilter(), name))
            times.append(time.perf_counter() - started)
        seconds = min(times)
        result[name] = {"rows_per_s": args.runs / seconds, "seconds": seconds, "bytes": size}
    if args.json:
        print(json.dumps(result))
        return
    for name in ("csv", "json"):
        print(f"{name}: {args.runs} runs in {result[name]['seconds']:.2f} s, {result[name]['rows_per_s']:,.0f} rows/s")


if __name__ == "__main__":
    main()
