"""The gait readout of simulate mode: the paper's gaits as presets, and the search for the gait
(period 1, 2 or 4) of the sliders' controls (:func:`find_gait`, run in the mode's background
worker)."""

from __future__ import annotations

from frontend.viewer.simulated_climb import Controls
from sim_core import ControlSchedule, FixedPoint
from sim_core.model.errors import NoGaitFound
from sim_core.model.presets import PAPER_GAITS, START_GUESS
from sim_core.section.gait_search import gait_of


def _preset_label(name: str, pairs: tuple[tuple[float, float], ...]) -> str:
    """``"period 2 · 30°/30° · 0.87/0.90"``: zeta0 with at least two decimals."""
    angles = "/".join(f"{psi0:g}°" for psi0, _ in pairs)
    lengths = "/".join(f"{zeta0:.2f}" if round(zeta0, 2) == zeta0 else f"{zeta0:g}" for _, zeta0 in pairs)
    return f"{name} · {angles} · {lengths}"


# The paper's gaits (Fig. 7, sim_core.model.presets.PAPER_GAITS): psi0 [deg] and zeta0 [l0] of the
# left and right legs; a one-pair gait is both legs'.
GAIT_PRESETS = {_preset_label(name, pairs): (pairs[0], pairs[-1]) for name, pairs in PAPER_GAITS.items()}
CUSTOM = "custom"
DEFAULT_START = START_GUESS  # section state when the controls have no stable gait to start on
GAIT_SEARCH_PERIOD = 4  # the readout looks for gaits of period 1, 2 and 4 (the paper's)


def find_gait(controls: Controls, guess) -> tuple[FixedPoint | None, str]:
    """The gait (period 1, 2 or 4) of ``controls`` near ``guess``, or the best a grid search finds,
    and a line describing it. Runs in the view's background worker (plain, non-parallel kernels)."""
    model = controls.robot.to_model()
    legs = (controls.left,) if controls.left == controls.right else (controls.left, controls.right)
    schedule = ControlSchedule.of(*legs)
    try:
        gait = gait_of(model, schedule, GAIT_SEARCH_PERIOD, guess, grid=(4, 4), prefer_stable=True)
    except NoGaitFound:
        return None, "none found (a grid search of period 1, 2 and 4 found no gait)"
    climb_cm = 100 * gait.climb_per_period / gait.period * controls.robot.leg_length
    stability = "stable" if gait.stable else "**unstable**"
    state = ", ".join(f"{v:.3f}" for v in gait.state)
    return gait, (
        f"period {gait.period}, {stability}, max|λ| = {gait.max_abs_eigenvalue:.3f}, "
        f"{gait.motion} {climb_cm:+.2f} cm/jump, fixed point ({state})"
    )
