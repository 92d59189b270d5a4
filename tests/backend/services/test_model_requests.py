"""A request's model and controls as sim_core's."""

from backend.schemas import LegIn, ModelIn
from backend.services.model_requests import model_params, schedule_of


def test_model_params_start_from_the_preset(paper):
    assert model_params(ModelIn()) == paper
    changed = model_params(ModelIn(alpha=40.0, mu=1.5))
    assert (changed.alpha, changed.mu, changed.d_hat, changed.c_zeta) == (40.0, 1.5, paper.d_hat, paper.c_zeta)


def test_schedule_of_keeps_the_legs_in_order(alternating):
    legs = [LegIn(psi0_deg=30.0, zeta0=0.87), LegIn(psi0_deg=30.0, zeta0=0.9)]
    assert schedule_of(legs) == alternating
