"""What every job kind shares (backend/jobs/base.py): a request's legs as sim_core's schedule."""

from backend.jobs.base import schedule_of
from backend.schemas import LegIn


def test_schedule_of_keeps_the_legs_in_order(alternating):
    legs = [LegIn(psi0_deg=30.0, zeta0=0.87), LegIn(psi0_deg=30.0, zeta0=0.9)]
    assert schedule_of(legs) == alternating
