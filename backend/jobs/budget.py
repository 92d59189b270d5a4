"""A job's work checked against the budget one job may take (the budget itself, the queue's and
the worker's rate: :mod:`backend.schemas.job_budget`), and the basin cell's worst case that the
sweep and the basin share."""

from __future__ import annotations

from backend.jobs.base import WorstCase
from backend.schemas.job_budget import WORK_BUDGET_JUMPS

# A basin's cells still undecided at its first cap may go on, the cap doubled, up to a jump limit:
# the limit, not the first cap, is a cell's worst case.
BASIN_JUMP_LIMIT = 100_000
JUMP_LIMIT_DESCRIPTION = "cells undecided at the first cap go on up to this many jumps [jumps]; none: no continuation"


def basin_cell_jumps(first_cap: int, jump_limit: int | None, cap_name: str, limit_name: str) -> tuple[int, str]:
    """A basin cell's jumps at its worst and the field that sets them: the jump limit, which may
    not be below the first cap, or the first cap where there is no limit (None)."""
    if jump_limit is None:
        return first_cap, cap_name
    if jump_limit < first_cap:
        raise ValueError(f"{limit_name} must be at least {cap_name}, got {jump_limit} < {first_cap}")
    return jump_limit, limit_name


def within_budget(job, worst_case: WorstCase):
    """``job`` if its worst-case work (``(jumps, formula)``) fits the budget; a ValueError saying so otherwise."""
    jumps, formula = worst_case
    if jumps > WORK_BUDGET_JUMPS:
        raise ValueError(
            f"the job would take up to {jumps:.3g} jumps ({formula}), over the limit of {WORK_BUDGET_JUMPS:.3g} "
            "(about an hour of the job worker); ask for less, or split it into several jobs"
        )
    return job
