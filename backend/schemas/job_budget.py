"""What a job may cost: its work counted in jumps at its worst, the budget one job and the queue
may take, and the job worker's rate for estimates. For request bodies and stored specs alike
(:func:`worst_case_jumps` reads only the fields both have)."""

from __future__ import annotations

from sim_core.robustness.mfpt_grid import ChainGrid

# A job's work, in jumps at its worst (every trial to its cap, every basin point to its jump limit):
# about an hour of the job worker on the lab's machine (1.35e5-1.6e5 jumps/s measured by
# scripts/bench_job_rate.py on 2 cores). Larger jobs are refused with a 422 naming the limit.
WORK_BUDGET_JUMPS = 500_000_000
# The queue's budget: queued and running work together (each job at its worst, a running one's
# share still to do), about eight hours of the job worker; one client (a script, the panel) may
# hold at most CLIENT_SHARE of it, so another always finds room. Past either, a 429 says so.
QUEUE_BUDGET_JUMPS = 8 * WORK_BUDGET_JUMPS
CLIENT_SHARE = 0.5
MAX_QUEUED_JOBS = 1000  # jobs waiting at once, however small
JOB_RATE_JUMPS_PER_S = 135_000  # the job worker's rate (the low end of scripts/bench_job_rate.py): for estimates
GAIT_SEARCH_JUMPS = 1000  # a gait search's work per guess, at most (Levenberg–Marquardt's map evaluations)
# The MFPT chain in the job worker: at most this many (velocity node, pitch) pairs a grid, so that
# the worst case (both grids, the finest rule) stays within the work budget.
MFPT_MAX_PAIRS = 600_000
MFPT_MAX_GRID = 60
# A basin's cells still undecided at its first cap may go on, the cap doubled, up to a jump limit:
# the limit, not the first cap, is a cell's worst case.
BASIN_JUMP_LIMIT = 100_000
JUMP_LIMIT_DESCRIPTION = "cells undecided at the first cap go on up to this many jumps [jumps]; none: no continuation"
# The viability map: one jump a state-action pair; 120² x 40² (23 million pairs, ~3 minutes of
# the job worker) at most, and its result (kernel, measure, viable pairs as bits) stays a few MB.
VIABILITY_MAX_STATES = 120
VIABILITY_MAX_ACTIONS = 40
# A controller's MFPT by splitting (sim_core.robustness.splitting): its work is AMS runs of replicas, each
# replica's excursions ended home, at a failure or at SplittingOptions' excursion_limit (20,000
# jumps). One replica's share of a run is counted at that limit, the long run and climbs that
# measure the holding state before them at theirs (pilot_jumps + climbs x excursion_limit, the
# defaults): far above what they take (0.8-24 ms a replica-run measured, pid to deadbeat at velocity
# noise 0.05, 2 cores: 100-3,300 jumps at the job rate) but a rarer failure takes more levels. So
# replicas x runs is bounded, and the worst case stays within the work budget.
LOOP_MFPT_REPLICA_JUMPS = 20_000
LOOP_MFPT_SETUP_JUMPS = 20_000 + 200 * 20_000
LOOP_MFPT_MAX_REPLICA_RUNS = 20_000


def mfpt_grid_of(job) -> ChainGrid:
    """The chain's grid of an MFPT job (request body or stored spec)."""
    return ChainGrid(velocity_nodes=job.grid, pitch_spacing=job.pitch_spacing, max_pairs=MFPT_MAX_PAIRS)


def worst_case_jumps(job) -> tuple[int, str]:
    """A job's work in jumps at its worst, and the formula that counts it: for a request body or a
    stored spec alike (both have the fields this reads)."""
    if job.kind == "mjtf":
        return len(job.zeta0s) * job.trials * job.cap, "levels x trials x cap"
    if job.kind == "sweep":
        cell, name = basin_cell_jumps(job.basin_jumps, job.basin_jump_limit, "basin_jumps", "basin_jump_limit")
        return job.steps * job.basin_grid**2 * cell, f"steps x basin_grid² x {name}"
    if job.kind == "basin":
        cell, name = basin_cell_jumps(job.jumps, job.jump_limit, "jumps", "jump_limit")
        return job.grid**2 * cell, f"grid² x {name}"
    if job.kind == "control-study":
        return len(job.controllers) * job.seeds * job.jumps, "controllers x seeds x jumps"
    if job.kind == "viability":
        return job.states**2 * job.actions**2, "states² x actions²"
    if job.kind == "loop-mfpt":
        jumps = job.replicas * job.runs * LOOP_MFPT_REPLICA_JUMPS + LOOP_MFPT_SETUP_JUMPS
        return jumps, f"replicas x runs x {LOOP_MFPT_REPLICA_JUMPS} + {LOOP_MFPT_SETUP_JUMPS} for the holding state"
    if job.kind == "mfpt":
        drifts = job.noise.pitch_drift_deg > 0.0
        return mfpt_grid_of(job).worst_case_jumps(drifts), "2 grids x (pairs x draws + paths x path jumps)"
    return job.grid**2 * GAIT_SEARCH_JUMPS, f"grid² x {GAIT_SEARCH_JUMPS}"


def basin_cell_jumps(first_cap: int, jump_limit: int | None, cap_name: str, limit_name: str) -> tuple[int, str]:
    """A basin cell's jumps at its worst and the field that sets them: the jump limit, which may
    not be below the first cap, or the first cap where there is no limit (None)."""
    if jump_limit is None:
        return first_cap, cap_name
    if jump_limit < first_cap:
        raise ValueError(f"{limit_name} must be at least {cap_name}, got {jump_limit} < {first_cap}")
    return jump_limit, limit_name


def within_budget(job):
    """``job`` if its worst-case work fits the budget."""
    jumps, formula = worst_case_jumps(job)
    if jumps > WORK_BUDGET_JUMPS:
        raise ValueError(
            f"the job would take up to {jumps:.3g} jumps ({formula}), over the limit of {WORK_BUDGET_JUMPS:.3g} "
            "(about an hour of the job worker); ask for less, or split it into several jobs"
        )
    return job
