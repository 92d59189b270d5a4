"""History's pages at 100,000 runs: latency of ``GET /api/v1/runs`` under 20 clients, side by side
with a base revision.

Seeds ``--runs`` runs (simulations, live robot runs — open and closed loop, ended by "jumps done",
an e-stop, a fall, a lost link, an error — and replays, with tags and notes) straight into a
SQLite store at migration 0007 (the schema before the run outcome columns; bulk inserts of the
models' columns, not the API), copies it for each side, upgrades the new side's copy to the newest
schema (timed: migration 0008 backfills every run), and starts ``parkour serve`` on each: ``--base``
checked out into a temporary git worktree, and this working tree. Then, in alternating phases (the
order flips each round, so a slow minute of this shared machine hits both alike), ``--clients``
clients each loop over pages of 50 on their own keep-alive connection, no pause:

- ``common``: what both revisions answer — sorted by id, climb, zeta0, creation, duration, filtered
  by kind, status, tag, a zeta0 range, at random offsets deep into the list;
- ``new``: what only this tree answers (the new side alone) — every page's total, sorts by end
  reason, target, jumps, filters by end reason, loop and controller, a search of notes and tags,
  any page by offset in the id order.

Prints p50/p95/max per side and set, and the new/base ratios per round. ``--writes 0.05`` makes
that fraction of requests store a run (each commit makes the read workers count totals afresh).
``--searchers 10`` adds that many clients beside them, each searching notes and tags for random
text (3 to 8 letters, which mostly matches nothing: ``search`` in the output), as people typing
into History's search box do; the other clients' pages show what the searches cost everyone.
``--same-queries`` asks the base the new queries too, for a base that answers them.
Usage: PYTHONPATH=. python scripts/bench_history_page.py --base REV [--runs 100000] [--clients 20]
       [--rounds 3] [--seconds 8] [--writes 0] [--searchers 0] [--same-queries]
"""

from __future__ import annotations

import argparse
import asyncio
import concurrent.futures
import datetime
import json
import multiprocessing
import random
import re
import shutil
import statistics
import subprocess
import tempfile
import time
import urllib.parse
from pathlib import Path

import httpx
from bench_load import RUN, Connection, cpu_seconds, machine_cpu_seconds  # scripts/ is on the path
from bench_store import run_row
from sqlalchemy import MetaData, insert

from backend.store.database import make_engine, migrate, sqlite_url
from backend.store.models import RunTag
from tests.helpers import start_service

ROOT = Path(__file__).resolve().parents[1]
BASE_SCHEMA = "0007"  # the runs table before its outcome columns (migration 0008)
TAGS = ["fig8", "fig11", "robot-a", "robot-b", "baseline", "noisy", "pid", "sweep", "wet-wall", "seed-1"]
NOTES = ["", "", "", "", "left foot slipped on jump 3", "wet wall after rain", "battery low", "retest with psi0 32",
         "Slipped twice; marker 2 lost", "clean climb"]  # fmt: skip
ENDINGS = ["jumps done"] * 6 + ["stopped", "time limit", "e-stop", "link lost", "robot disarmed (fell or timed out)",
                                "error: the link write timed out"]  # fmt: skip
CLOSED_LOOP = {"target_m": 0.55, "kp": 0.04, "ki": 0.0, "kd": 0.02, "zeta0_min": 0.8, "zeta0_max": 0.98}
EPOCH = datetime.datetime(2026, 1, 1, tzinfo=datetime.UTC)
CLIENT_PROCESSES = 2
PAGE = 50
# (params, deepest page asked for): a random offset in [0, pages) * PAGE where pages > 1.
COMMON = [
    ({"sort": "-id"}, 1),
    ({"sort": "-climb"}, 2000),
    ({"sort": "zeta0"}, 2000),
    ({"sort": "-created_at", "kind": "robot"}, 400),
    ({"sort": "-id", "tag": "fig8"}, 1),
    ({"sort": "-duration_s", "status": "failed"}, 100),
    ({"sort": "-climb", "zeta0_min": 0.85, "zeta0_max": 0.9}, 50),
]
NEW = [
    ({"sort": "-id"}, 2000),  # any page by offset, sorted by id
    ({"sort": "-id", "end_reason": "e-stop"}, 20),
    ({"sort": "-target", "loop": "closed"}, 50),
    ({"sort": "-id", "q": "slip"}, 20),
    ({"sort": "end_reason"}, 2000),
    ({"sort": "-jumps_completed"}, 2000),
    ({"sort": "kind", "controller": "pid", "status": "failed"}, 10),
    ({"sort": "-climb", "tag": "wet-wall", "kind": "sim"}, 50),
]


def schema_of(tree: Path) -> str:
    """The newest migration of the checkout at ``tree``: the schema its service expects."""
    versions = tree / "backend" / "store" / "migrations" / "versions"
    found = {}
    for path in versions.glob("*.py"):
        text = path.read_text()
        revision = re.search(r'^revision = "(\w+)"', text, re.M)
        down = re.search(r'^down_revision = "(\w+)"', text, re.M)
        if revision:
            found[revision.group(1)] = down.group(1) if down else None
    heads = set(found) - set(found.values())
    if len(heads) != 1:
        raise SystemExit(f"{versions}: expected one newest migration, found {sorted(heads)}")
    return heads.pop()


def seed(url: str, count: int, rng: random.Random, schema: str = BASE_SCHEMA) -> None:
    """``count`` runs at migration ``schema`` (a base revision's, which its service can open): the
    models' columns that the table has then."""
    engine = make_engine(url)
    migrate(engine, schema)
    metadata = MetaData()
    metadata.reflect(engine, only=["runs", "run_tags"])
    runs, columns = metadata.tables["runs"], set(metadata.tables["runs"].columns.keys())
    with engine.begin() as connection:
        for start in range(0, count, 10_000):
            rows, tags = [], []
            for run_id in range(start + 1, min(start + 10_000, count) + 1):
                rows.append({key: value for key, value in _run(run_id, rng).items() if key in columns})
                tags += [{"run_id": run_id, "tag": tag} for tag in rng.sample(TAGS, rng.randrange(4))]
            connection.execute(insert(runs), rows)
            connection.execute(insert(RunTag), tags)
    engine.dispose()


def _run(run_id: int, rng: random.Random) -> dict:
    """One run's row: a simulation (70%), a live robot run (25%, a third closed loop) or a replay."""
    zeta0, psi0 = rng.uniform(0.8, 0.98), rng.uniform(15, 45)
    kind = rng.choices(["sim", "robot", "replay"], weights=[70, 25, 5])[0]
    failure = rng.choice([None, None, None, "slip", "no_flight", "collapse"]) if kind == "sim" else None
    jumps_completed = 20 if failure is None else rng.randrange(20)
    results: dict = {"states": [[-0.93, -0.17]] * (jumps_completed + 1), "rises": [0.33] * jumps_completed}
    status = "done"
    if kind == "sim":
        results["failure"] = None if failure is None else {"jump": jumps_completed + 1, "code": failure}
    else:
        touchdowns = rng.randrange(1, 21)
        jumps_completed = touchdowns - 1
        results["touchdowns"] = [{"index": k} for k in range(touchdowns)]
    if kind == "robot":
        ending = rng.choice(ENDINGS)
        status = "done" if ending in ("jumps done", "stopped", "time limit") else "failed"
        closed = rng.random() < 1 / 3
        results |= {"end_reason": ending, "closed_loop": CLOSED_LOOP | {"target_m": rng.choice([0.4, 0.55])} if closed
                    else None}  # fmt: skip
    elif kind == "replay":
        results["source_run_id"] = max(1, run_id - rng.randrange(1, 50))
    return run_row(run_id, psi0, zeta0, failure, jumps_completed, rng) | {
        "kind": kind,
        "status": status,
        "duration_s": rng.uniform(0.001, 60 if kind == "robot" else 0.5),
        "created_at": EPOCH + datetime.timedelta(minutes=run_id + rng.uniform(0, 30)),
        "controls": [[psi0, zeta0], [psi0, zeta0]] if kind != "sim" else [[psi0, zeta0]],
        "results": results,
        "notes": rng.choice(NOTES),
    }


SEARCHED = "abcdefghijklmnopqrstuvwxyz"


def _searches(rng: random.Random):
    """A searcher's queries: random text of 3 to 8 letters, newest runs first."""
    while True:
        text = "".join(rng.choice(SEARCHED) for _ in range(rng.randint(3, 8)))
        yield "search", ({"sort": "-id", "q": text}, 1)


async def _client(host: str, port: int, token: str, deadline: float, queries: list, writes: float, seed_value: int,
                  searcher: bool = False):  # fmt: skip
    """One client: (set, latency [s], status, has a total) of each request until ``deadline``
    (``searcher``: only searches for random text, never a write)."""
    rng, out, connection = random.Random(seed_value), [], Connection(host, port)
    searches = _searches(rng) if searcher else None
    write_headers = {"Authorization": f"Bearer {token}", "Content-Type": "application/json"}
    body = json.dumps(RUN).encode()
    while time.monotonic() < deadline:
        if searches is None and rng.random() < writes:
            started = time.perf_counter()
            status = await connection.request("POST", "/api/v1/runs", write_headers, body)
            out.append(("write", time.perf_counter() - started, status))
            continue
        name, (params, pages) = next(searches) if searches is not None else rng.choice(queries)
        query = urllib.parse.urlencode(params | {"limit": PAGE, "offset": PAGE * rng.randrange(pages)})
        started = time.perf_counter()
        status = await connection.request("GET", f"/api/v1/runs?{query}", {})
        out.append((name, time.perf_counter() - started, status))
    return out


def _client_process(base: str, token: str, seconds: float, clients: int, queries: list, writes: float, first: int,
                    searchers: int = 0):  # fmt: skip
    host, _, port = urllib.parse.urlsplit(base).netloc.partition(":")

    async def run() -> list:
        deadline = time.monotonic() + seconds
        tasks = [_client(host, int(port), token, deadline, queries, writes, first + k) for k in range(clients)]
        tasks += [_client(host, int(port), token, deadline, queries, writes, first + 500 + k, searcher=True)
                  for k in range(searchers)]  # fmt: skip
        return [request for client in await asyncio.gather(*tasks) for request in client]

    return asyncio.run(run())


def service_cpu(pid: int) -> tuple[float, float]:
    """CPU seconds so far of the service's own process and of its children (the read and compute
    workers), from /proc (Linux)."""
    children = []
    for task in Path(f"/proc/{pid}/task").iterdir():
        children += (task / "children").read_text().split()
    return cpu_seconds(pid), sum(cpu_seconds(int(child)) for child in children)


def phase(
    base: str,
    token: str,
    clients: int,
    seconds: float,
    queries: list,
    writes: float,
    seed_value: int,
    pid: int = 0,
    searchers: int = 0,
) -> dict:
    """``clients`` clients (and ``searchers`` searching at random) for ``seconds``: per set of
    queries, p50/p95/max [ms] and requests, and the CPU per request of the service's process, its
    workers and the whole machine [ms]."""
    before = service_cpu(pid) if pid else (0.0, 0.0)
    machine_before = machine_cpu_seconds()
    per_process = [clients // CLIENT_PROCESSES + (k < clients % CLIENT_PROCESSES) for k in range(CLIENT_PROCESSES)]
    searching = [searchers // CLIENT_PROCESSES + (k < searchers % CLIENT_PROCESSES) for k in range(CLIENT_PROCESSES)]
    context = multiprocessing.get_context("spawn")
    with concurrent.futures.ProcessPoolExecutor(CLIENT_PROCESSES, mp_context=context) as pool:
        futures = [pool.submit(_client_process, base, token, seconds, n, queries, writes, seed_value + 1000 * k,
                               searching[k])
                   for k, n in enumerate(per_process) if n or searching[k]]  # fmt: skip
        requests = [request for future in futures for request in future.result()]
    summary = {"requests": len(requests), "per_s": len(requests) / seconds,
               "errors": sorted({status for _, _, status in requests if status >= 400})}  # fmt: skip
    count = max(len(requests), 1)
    summary["machine_cpu_ms"] = 1e3 * (machine_cpu_seconds() - machine_before) / count
    if pid:
        after = service_cpu(pid)
        summary["service_cpu_ms"] = 1e3 * (after[0] - before[0]) / count
        summary["workers_cpu_ms"] = 1e3 * (after[1] - before[1]) / count
    for name in sorted({name for name, _, _ in requests}):
        times = sorted(latency for kind, latency, _ in requests if kind == name)
        summary[name] = {"count": len(times), "p50_ms": 1e3 * statistics.median(times),
                         "p95_ms": 1e3 * times[int(0.95 * (len(times) - 1))], "max_ms": 1e3 * times[-1]}  # fmt: skip
    return summary


def check_pages(base: str) -> None:
    """The new side's pages carry their total and page through by offset in every order."""
    with httpx.Client(base_url=base, timeout=60) as client:
        for params, _ in NEW + COMMON:
            first = client.get("/api/v1/runs", params=params | {"limit": PAGE}).json()
            assert isinstance(first["total"], int), params
            if first["total"] > PAGE:
                second = client.get("/api/v1/runs", params=params | {"limit": PAGE, "offset": PAGE}).json()
                overlap = {run["id"] for run in first["items"]} & {run["id"] for run in second["items"]}
                assert not overlap and second["total"] == first["total"], params


def stop_sides(processes: dict, git_worktree: list, base_tree: Path, scratch: Path) -> None:
    """End a side-by-side bench: both services stopped, the base's worktree and the scratch folder gone."""
    for process in processes.values():
        process.terminate()
        process.wait(30)
    if base_tree.exists():
        subprocess.run([*git_worktree, "remove", "--force", str(base_tree)], check=False)
    shutil.rmtree(scratch, ignore_errors=True)


def side_by_side_options(doc: str, *, runs: int, rounds: int, seconds: float, port: int) -> argparse.ArgumentParser:
    """The options of a bench that runs a base revision and this tree side by side, with its defaults."""
    parser = argparse.ArgumentParser(description=doc.splitlines()[0])
    parser.add_argument("--base", default="HEAD", help="the revision to compare against (default: the last commit)")
    parser.add_argument("--runs", type=int, default=runs)
    parser.add_argument("--clients", type=int, default=20)
    parser.add_argument("--rounds", type=int, default=rounds)
    parser.add_argument("--seconds", type=float, default=seconds, help="each phase's length")
    parser.add_argument("--port", type=int, default=port, help="the base's port; the new one's is the next")
    return parser


def main() -> None:
    parser = side_by_side_options(__doc__, runs=100_000, rounds=3, seconds=8.0, port=8791)
    parser.add_argument("--writes", type=float, default=0.0, help="the fraction of requests that store a run")
    parser.add_argument("--searchers", type=int, default=0, help="clients beside them, each searching for random text")
    parser.add_argument(
        "--same-queries",
        action="store_true",
        help="ask the base the new queries too (a base from issue 26 on answers them): both sides do the same work",
    )
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args()
    scratch = Path(tempfile.mkdtemp(prefix="parkourlab-history-"))
    base_tree = scratch / "base-tree"
    base_queries = COMMON + NEW if args.same_queries else COMMON
    sides = {"base": (base_tree, args.port, base_queries), "new": (ROOT, args.port + 1, COMMON + NEW)}
    processes: dict[str, subprocess.Popen] = {}
    results: dict = {"runs": args.runs, "clients": args.clients, "base": args.base, "rounds": {"base": [], "new": []}}
    git_worktree = ["git", "-C", str(ROOT), "worktree"]
    try:
        if subprocess.run([*git_worktree, "add", "--detach", "-q", str(base_tree), args.base]).returncode:
            raise SystemExit(f"--base {args.base!r} is no revision git can check out (git said why, above)")
        (scratch / "seed").mkdir()
        began = time.perf_counter()
        seed(sqlite_url(scratch / "seed"), args.runs, random.Random(0))
        results["seed_s"] = time.perf_counter() - began
        tokens = {}
        for name, (tree, port, _) in sides.items():
            shutil.copytree(scratch / "seed", scratch / name)
            if name == "new":
                engine = make_engine(sqlite_url(scratch / name))
                began = time.perf_counter()
                migrate(engine)  # 0008: the outcome columns, backfilled from every run's results
                results["migrate_s"] = time.perf_counter() - began
                engine.dispose()
            processes[name] = start_service(scratch / name, port, "--no-view", tree=tree)
            tokens[name] = (scratch / name / "api_token").read_text().strip()
        check_pages(f"http://127.0.0.1:{sides['new'][1]}")
        for name, (_, port, queries) in sides.items():  # warm: the database's pages, the workers
            phase(f"http://127.0.0.1:{port}", tokens[name], 4, 3.0, _named(queries), 0.0, 7)
        for round_ in range(args.rounds):
            for name in sides if round_ % 2 == 0 else reversed(list(sides)):
                _, port, queries = sides[name]
                entry = phase(f"http://127.0.0.1:{port}", tokens[name], args.clients, args.seconds, _named(queries),
                              args.writes, round_, processes[name].pid, args.searchers)  # fmt: skip
                results["rounds"][name].append(entry)
    finally:
        stop_sides(processes, git_worktree, base_tree, scratch)
    if args.json:
        print(json.dumps(results))
        return
    _report(results, args)


def _named(queries: list) -> list:
    """Each query with the set it belongs to: ``common`` (both revisions) or ``new``."""
    return [("common" if query in COMMON else "new", query) for query in queries]


def _report(results: dict, args) -> None:
    print(f"{args.runs:,} runs (seeded in {results['seed_s']:.0f} s; migrations 0008 on, on them: "
          f"{results['migrate_s']:.1f} s), {args.clients} clients, {args.rounds} rounds of {args.seconds:g} s "
          f"per side, writes {args.writes:.0%}, {args.searchers} searching beside them; "
          f"base = {args.base}")  # fmt: skip
    rounds = results["rounds"]
    for name, entries in rounds.items():
        for kind in ("common", "new", "write", "search"):
            if kind not in entries[0]:
                continue
            p50 = statistics.median(entry[kind]["p50_ms"] for entry in entries)
            p95 = statistics.median(entry[kind]["p95_ms"] for entry in entries)
            worst = max(entry[kind]["p95_ms"] for entry in entries)
            count = sum(entry[kind]["count"] for entry in entries)
            print(f"{name:>5} {kind:>6}: p50 {p50:6.1f} ms, p95 {p95:6.1f} ms (worst round {worst:6.1f}), "
                  f"{count} requests, {statistics.median(e['per_s'] for e in entries):.0f}/s all kinds, "
                  f"errors {sorted({s for e in entries for s in e['errors']}) or 'none'}")  # fmt: skip
    for name, entries in rounds.items():
        cpu = {key: statistics.median(entry[key] for entry in entries)
               for key in ("service_cpu_ms", "workers_cpu_ms", "machine_cpu_ms")}  # fmt: skip
        print(f"{name:>5} CPU per request: service {cpu['service_cpu_ms']:.2f} ms, its workers "
              f"{cpu['workers_cpu_ms']:.2f} ms, the whole machine {cpu['machine_cpu_ms']:.2f} ms (clients and "
              "other programs included)")  # fmt: skip
    ratios = [new["common"]["p95_ms"] / base["common"]["p95_ms"] for new, base in zip(rounds["new"], rounds["base"],
                                                                                       strict=True)]  # fmt: skip
    print("common pages' p95, new / base, per round:", ", ".join(f"{ratio:.2f}" for ratio in ratios))


if __name__ == "__main__":
    main()
