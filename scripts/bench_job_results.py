"""``GET /api/v1/jobs/{id}/results`` of a big MJTF job: the service's level summaries, timed.

Stores one MJTF job with ``--levels`` x ``--trials`` trials (random jumps and outcomes, written
straight to a scratch SQLite file), then times ``backend.services.jobs.level_summaries`` — what
the route computes — as the median of ``--repeats``. Run it on two checkouts to compare them.
"""

from __future__ import annotations

import argparse
import json
import statistics
import tempfile
import time
from pathlib import Path

import numpy as np

from backend.jobs.mjtf import MJTFJobCreate
from backend.services import jobs
from backend.store.database import make_engine, migrate, session_factory, sqlite_url
from backend.store.models import Trial
from sim_core.model.failures import Failure


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--levels", type=int, default=11)
    parser.add_argument("--trials", type=int, default=9200)  # 11 x 9200 = 101,200 trials
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args()
    engine = make_engine(sqlite_url(Path(tempfile.mkdtemp())))
    migrate(engine)
    sessions = session_factory(engine)
    rng = np.random.default_rng(0)
    with sessions() as session:
        zeta0s = [0.85 + 0.001 * k for k in range(args.levels)]
        job = jobs.create_job(session, MJTFJobCreate(zeta0s=zeta0s, trials=args.trials, cap=1000))
        codes = [None, *(failure.code for failure in Failure)]
        session.add_all(
            Trial(job_id=job.id, level=level, index=index, zeta0=zeta0s[level], seed=index,
                  jumps=int(rng.integers(1, 1000)), failure_code=codes[int(rng.integers(0, len(codes)))])
            for level in range(args.levels) for index in range(args.trials)
        )  # fmt: skip
        session.commit()
        times = []
        for _ in range(args.repeats):
            started = time.perf_counter()
            jobs.level_summaries(session, job)
            times.append(time.perf_counter() - started)
    result = {"trials": args.levels * args.trials, "median_s": statistics.median(times), "min_s": min(times)}
    print(json.dumps(result) if args.json else f"{result['trials']} trials: median {result['median_s'] * 1e3:.0f} ms")


if __name__ == "__main__":
    main()
