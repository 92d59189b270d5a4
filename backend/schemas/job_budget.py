"""What a job may cost: the budget one job and the queue may take, in jumps at their worst, and the
job worker's rate for estimates. Each kind counts its own work (``worst_case`` in its module of
:mod:`backend.jobs`); :func:`backend.jobs.budget.within_budget` holds a request to the budget."""

from __future__ import annotations

# A job's work, in jumps at its worst (every trial to its cap, every basin point to its jump limit):
# about an hour of the job worker on the lab's machine (1.35e5-1.6e5 jumps/s measured by
# scripts/bench_job_rate.py on 2 cores). Larger jobs are refused with a 422 naming the limit.
WORK_BUDGET_JUMPS = 500_000_000
# The queue's budget: queued and running work together (each job at its worst, a running one's
# share still to do), about eight hours of the job worker; one person (whatever tools they submit
# through: their token names them) may hold at most PERSON_SHARE of it, and have at most
# PERSON_QUEUED_JOBS waiting, so another always finds room. Past any of these, a 429 says so.
QUEUE_BUDGET_JUMPS = 8 * WORK_BUDGET_JUMPS
PERSON_SHARE = 0.5
MAX_QUEUED_JOBS = 1000  # jobs waiting at once, however small
PERSON_QUEUED_JOBS = 250  # one person's jobs waiting at once: a flood of small ones leaves room for others
JOB_RATE_JUMPS_PER_S = 135_000  # the job worker's rate (the low end of scripts/bench_job_rate.py): for estimates
