"""How long submitting a job takes with the queue empty and with ``--queued`` jobs waiting.

Each submission checks the queue's room (every unfinished job's work at its worst, the person's
share) and answers the new job's place and estimate (every unfinished job's standing): work that
grows with the queue. An adversary found POST /jobs at 25 ms median with an empty queue and 110 ms
with 300 queued (issue 40). This times ``services.jobs.create_job`` in-process on a SQLite store
in a temporary folder (no runner: the jobs stay queued), ``--samples`` submissions at each queue
length, and prints the medians and their ratio.
Usage: PYTHONPATH=. python scripts/bench_job_submit.py [--queued 300] [--samples 40]
"""

from __future__ import annotations

import argparse
import statistics
import tempfile
import time
from pathlib import Path

from backend.jobs.mjtf import MJTFJobCreate
from backend.services import jobs
from backend.store.database import make_engine, migrate, session_factory, sqlite_url

BODY = {"zeta0s": [0.9], "trials": 2, "cap": 20}


def timed_submissions(sessions, count: int) -> list[float]:
    """``count`` submissions' times [s], each in a session of its own, as a request has, from ten
    people in turn (one may have at most 250 jobs waiting)."""
    times = []
    for k in range(count):
        with sessions() as session:
            started = time.perf_counter()
            jobs.create_job(session, MJTFJobCreate(**BODY), person=f"person-{k % 10}")
            times.append(time.perf_counter() - started)
    return times


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--queued", type=int, default=300)
    parser.add_argument("--samples", type=int, default=40)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as folder:
        engine = make_engine(sqlite_url(Path(folder)))
        migrate(engine)
        sessions = session_factory(engine)
        empty = statistics.median(timed_submissions(sessions, args.samples))
        timed_submissions(sessions, args.queued - args.samples)  # fill the queue
        full = statistics.median(timed_submissions(sessions, args.samples))
        engine.dispose()
    print(f"create_job median: {1e3 * empty:.1f} ms with 0-{args.samples} queued, {1e3 * full:.1f} ms with "
          f"{args.queued}-{args.queued + args.samples} queued: {full / empty:.1f}x")  # fmt: skip


if __name__ == "__main__":
    main()
