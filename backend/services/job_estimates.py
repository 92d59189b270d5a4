"""How long a job should take on this machine: expectations a person can plan by, beside the
worst-case bounds the queue admits by (:mod:`backend.services.job_queue`).

A job's worst case (every trial to its cap, every cell to its jump limit) is a bound, not a
forecast: an MFPT said 57 min at its worst and took 31 s. Each kind's jobs take a share of their
worst case that is their own — its pace, ``seconds × rate / worst jumps`` — which this machine
learns from the kind's newest done jobs (the median of their paces), starting from the kind's
``typical_fraction`` (:class:`backend.jobs.JobKind`) until it has run one. A job's expected time is
its pace times its worst case at the job worker's rate, plus a job's overhead — or, for a job this
machine has done before with the same spec, what that one took (an MFPT's chain comes from the
cache the second time: 0.05 s where the first took 11 s).

The paces are read from the store, as one snapshot per database and state of its done jobs: read
again only when another job is done, never changed in place.
"""

from __future__ import annotations

import json
import statistics
import threading
from collections.abc import Mapping
from dataclasses import dataclass, field
from types import MappingProxyType

from sqlalchemy.orm import Session

from backend.jobs import BY_NAME, UnreadableSpec, decode, worst_case_jumps
from backend.repositories import jobs as stored_jobs
from backend.schemas.job_budget import JOB_RATE_JUMPS_PER_S

OVERHEAD_S = 0.02  # a job's own cost whatever its work: claimed, handed to the worker, stored (0.01-0.02 s idle)
LEARNED_FROM = 20  # the newest done jobs of a kind whose paces it takes the median of
# A job shorter than this tells its overhead more than its pace (0.02 s of a 9,216-jump viability job
# would teach a pace of 0, and the next, 40 times larger, would be expected in 0.05 s: it took 0.4 s).
MIN_LEARNED_S = 4 * OVERHEAD_S
READ_DONE = 400  # done jobs read for the paces, newest first


@dataclass(frozen=True)
class Paces:
    """Each kind's pace (a share of its worst case) as this machine has run it; a kind it has not
    run takes its ``typical_fraction``. ``learned``: the done jobs each pace came from."""

    by_kind: Mapping[str, float] = field(default_factory=lambda: MappingProxyType({}))
    learned: Mapping[str, int] = field(default_factory=lambda: MappingProxyType({}))
    repeats: Mapping[str, float] = field(default_factory=lambda: MappingProxyType({}))  # spec_key -> [s]

    def of(self, kind: str) -> float:
        if kind in self.by_kind:
            return self.by_kind[kind]
        return BY_NAME[kind].typical_fraction if kind in BY_NAME else 1.0

    def expected_seconds(self, kind: str, worst_jumps: int, key: str | None = None) -> float:
        """[s] a job of ``kind`` with this worst case (and :func:`spec_key` ``key``) should take here."""
        if key is not None and key in self.repeats:
            return max(self.repeats[key], OVERHEAD_S)
        return OVERHEAD_S + self.of(kind) * worst_jumps / JOB_RATE_JUMPS_PER_S


def spec_key(kind: str, spec: dict) -> str:
    """What makes two jobs the same computation: the kind and the stored spec (its version and
    experiment left out)."""
    return kind + json.dumps({name: value for name, value in spec.items() if name not in _NOT_WORK}, sort_keys=True)


_NOT_WORK = ("version", "experiment_id")


def learned_paces(done: list[tuple[str, dict, object, object]]) -> Paces:
    """The paces of ``done`` jobs (``(kind, spec, started_at, finished_at)``, newest first)."""
    samples: dict[str, list[float]] = {}
    repeats: dict[str, float] = {}
    for kind, spec, started, finished in done:
        repeats.setdefault(spec_key(kind, spec), (finished - started).total_seconds())  # the newest of each
        if kind not in BY_NAME or len(samples.get(kind, ())) >= LEARNED_FROM:
            continue
        try:
            worst, _ = worst_case_jumps(decode(spec))
        except (UnreadableSpec, ValueError, TypeError):
            continue  # a spec of another version of the code
        seconds = (finished - started).total_seconds()
        if worst > 0 and seconds >= MIN_LEARNED_S:
            samples.setdefault(kind, []).append(max(seconds - OVERHEAD_S, 0.0) * JOB_RATE_JUMPS_PER_S / worst)
    by_kind = {kind: statistics.median(paces) for kind, paces in samples.items()}
    learned = {kind: len(paces) for kind, paces in samples.items()}
    return Paces(MappingProxyType(by_kind), MappingProxyType(learned), MappingProxyType(repeats))


_snapshots: dict[str, tuple[tuple[int, int], Paces]] = {}  # per database: (its done jobs' mark, paces)
_snapshots_lock = threading.Lock()


def paces(session: Session) -> Paces:
    """This database's paces: one query of its done jobs' count while none is added, else read again."""
    database = str(session.get_bind().url)
    mark = stored_jobs.done_mark(session)
    snapshot = _snapshots.get(database)
    if snapshot is not None and snapshot[0] == mark:
        return snapshot[1]
    fresh = learned_paces(stored_jobs.recent_done(session, READ_DONE))
    with _snapshots_lock:
        _snapshots[database] = (mark, fresh)
    return fresh
