"""The LQR designed on the return map (sim_core/control/return_map_lqr.py): its closed loop is stable on the
linearised map, and on the nonlinear model it brings the height to a target and holds it, for
models and targets it was not tuned on."""

import dataclasses
import math

import numpy as np
import pytest

from sim_core.basins.sweep import find_in_place_zeta0
from sim_core.control.return_map_lqr import delayed_system, design_lqr, linearised_map
from sim_core.control.study import controlled_loop
from sim_core.model.noise import NO_NOISE
from sim_core.model.presets import get_preset

PAPER = get_preset("paper").to_model()


def _climb(law, model, first_zeta0, jumps=60):
    """The noise-free climb under ``law`` from its gait's section state: (status, heights)."""
    kind, parameters = law.kernel_args()
    height, clipped = np.full(jumps + 1, math.nan), np.zeros(jumps, dtype=bool)
    arguments = (NO_NOISE.record(), model.record(), height, clipped)
    status, _ = controlled_loop(*law.state, math.radians(law.psi0_deg), first_zeta0, kind, parameters, 0, *arguments)
    return status, height


@pytest.mark.parametrize(("alpha", "psi0_deg", "rise"), [(None, 35.0, 0.1), (70.0, 33.0, 0.3), (85.0, 37.0, -0.05)])
def test_the_lqr_takes_the_height_to_a_target_and_holds_it(alpha, psi0_deg, rise):
    """From the gait of jumping in place, a target above or below: the height error vanishes
    (noise-free) and the closed loop of the linearised map has every eigenvalue inside the unit
    circle; models (alpha) and leg angles other than the paper's."""
    model = PAPER if alpha is None else dataclasses.replace(PAPER, alpha=alpha)
    psi0 = math.radians(psi0_deg)
    hover = find_in_place_zeta0(model, psi0)
    first_height = hover * math.sin(psi0)
    law = design_lqr(model, first_height + rise, psi0_deg, hover)
    phi, gamma = delayed_system(linearised_map(model, law.state, psi0, hover))
    gain = np.array(law.gain).reshape(2, 5)
    assert np.max(np.abs(np.linalg.eigvals(phi - gamma @ gain))) < 0.9
    status, height = _climb(law, model, hover)
    assert status == 0 and abs(height[-1] - law.target) < 1e-4
    assert np.all(np.abs(height[-10:] - law.target) < 1e-3)


def test_the_map_is_linearised_about_a_gait_of_jumping_in_place():
    psi0 = math.radians(35.0)
    hover = find_in_place_zeta0(PAPER, psi0)
    law = design_lqr(PAPER, 1.0, 35.0, hover)
    jacobian = linearised_map(PAPER, law.state, psi0, hover)
    assert jacobian.shape == (3, 6) and np.all(np.isfinite(jacobian))
    # Jumping in place: the state maps to itself and the body does not rise, so the map's own
    # state block has the gait's eigenvalues (|lambda| ~ 0.99: docs/model.md §4.2), inside the unit circle.
    assert 0.9 < np.max(np.abs(np.linalg.eigvals(jacobian[:2, :2]))) < 1.0


def test_a_model_gives_its_own_gains():
    psi0 = math.radians(35.0)
    other = dataclasses.replace(PAPER, alpha=70.0)
    paper_law = design_lqr(PAPER, 2.0, 35.0, find_in_place_zeta0(PAPER, psi0))
    other_law = design_lqr(other, 2.0, 35.0, find_in_place_zeta0(other, psi0))
    assert not np.allclose(paper_law.gain, other_law.gain, rtol=1e-3)
