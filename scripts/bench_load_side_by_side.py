"""The load benchmark as a ratio: this working tree's service against a base revision's, side by side.

This shared 2-core machine changes speed by up to 1.5x within minutes (the same code measured 138
and then 243 req/s ten minutes apart), so two bench_load.py runs one after the other compare the
machine, not the code. This script checks ``--base`` out into a temporary git worktree, starts
both services (``parkour serve``, each on its own copy of one store seeded at the base's schema
and migrated forward for this tree's) and loads them in
short alternating phases (the order flips each round), so a slow minute hits both alike. It
prints each side's medians and, per round, the ratios new / base of throughput, reads p95 and the
whole machine's CPU per request (the service's own process alone no longer says it all: the run
list's pages are read in worker processes).
Usage: PYTHONPATH=. python scripts/bench_load_side_by_side.py [--base HEAD] [--clients 20] [--rounds 5] [--seconds 4]
"""

from __future__ import annotations

import random
import shutil
import statistics
import subprocess
import tempfile
from pathlib import Path

from bench_history_page import (  # scripts/ is on the path when this script runs
    schema_of,
    seed,
    side_by_side_options,
    stop_sides,
)
from bench_load import phase

from backend.store.database import make_engine, migrate, sqlite_url
from tests.helpers import start_service

ROOT = Path(__file__).resolve().parents[1]


def median_of(phases: list[dict], *keys: str) -> float:
    """The median over ``phases`` (bench_load.phase summaries) of the value at ``keys``."""
    values = []
    for entry in phases:
        for key in keys:
            entry = entry[key]
        values.append(entry)
    return statistics.median(values)


def main() -> None:
    parser = side_by_side_options(__doc__, runs=20_000, rounds=5, seconds=4.0, port=8781)
    args = parser.parse_args()
    scratch = Path(tempfile.mkdtemp(prefix="parkourlab-sbs-"))
    base_tree = scratch / "base-tree"
    sides = {"base": (base_tree, args.port), "new": (ROOT, args.port + 1)}
    processes: dict[str, subprocess.Popen] = {}
    results: dict[str, list[dict]] = {name: [] for name in sides}
    try:
        git_worktree = ["git", "-C", str(ROOT), "worktree"]
        if subprocess.run([*git_worktree, "add", "--detach", "-q", str(base_tree), args.base]).returncode:
            raise SystemExit(f"--base {args.base!r} is no revision git can check out (git said why, above)")
        (scratch / "seed").mkdir()
        # Seeded at the base's schema, which its service can open; this tree's service gets its
        # copy migrated to this tree's newest first (as bench_history_page.py does).
        seed(sqlite_url(scratch / "seed"), args.runs, random.Random(0), schema=schema_of(base_tree))
        tokens = {}
        for name, (tree, port) in sides.items():
            shutil.copytree(scratch / "seed", scratch / name)
            if name == "new":
                engine = make_engine(sqlite_url(scratch / name))
                migrate(engine)
                engine.dispose()
            processes[name] = start_service(scratch / name, port, "--no-view", tree=tree)
            tokens[name] = (scratch / name / "api_token").read_text().strip()
            phase(f"http://127.0.0.1:{port}", tokens[name], 2, 2.0)  # warm: kernels, database pages
        for round_ in range(args.rounds):
            for name in sides if round_ % 2 == 0 else reversed(sides):
                url, pid = f"http://127.0.0.1:{sides[name][1]}", processes[name].pid
                results[name].append(phase(url, tokens[name], args.clients, args.seconds, pid))
    finally:
        stop_sides(processes, git_worktree, base_tree, scratch)
    print(f"{args.clients} clients, {args.rounds} rounds of {args.seconds:g} s per side; base = {args.base}")
    for name, phases in results.items():
        errors = [entry["errors"] for entry in phases if entry["errors"]]
        print(
            f"{name:>5}: {median_of(phases, 'per_s'):.0f} req/s, "
            f"{median_of(phases, 'service_cpu_ms_per_request'):.2f} ms CPU/request in the service's process, "
            f"{median_of(phases, 'machine_cpu_ms_per_request'):.2f} on the machine, "
            f"reads p95 {median_of(phases, 'read', 'p95_ms'):.0f} ms, "
            f"writes p95 {median_of(phases, 'write', 'p95_ms'):.0f} ms, errors {errors or 'none'}"
        )
    for label, keys in [
        ("req/s", ("per_s",)),
        ("reads p95", ("read", "p95_ms")),
        ("writes p95", ("write", "p95_ms")),
        ("machine CPU per request", ("machine_cpu_ms_per_request",)),
    ]:
        ratios = [
            median_of([new], *keys) / median_of([base], *keys)
            for new, base in zip(results["new"], results["base"], strict=True)
        ]
        print(f"{label}, new / base, per round:", ", ".join(f"{ratio:.2f}" for ratio in ratios))


if __name__ == "__main__":
    main()
