"""The jobs that study the section as a whole rather than one orbit: the MFPT chain (``parkour
mfpt``) and the viability kernel (``parkour viability``), run in the job worker; and, the MFPT's
other half, a closed-loop controller's by splitting (``parkour mfpt --controller``), which has no
section grid (the law's state is more than a grid holds) but the same figures.

A controller's MFPT reports its progress per splitting run (the runner stops the worker on a
cancel, or, on a Dask cluster, the progress call raises between runs); its draws all come from
the job's seed, so a restart recomputes the same result.

A viability job's result is ``parkour viability --json``'s figures and grids, with the viable
state-action pairs packed as bits (``viable_pairs``: base64 of ``numpy.packbits`` over the C-order
array of shape ``viable_pairs_shape`` = (xdot, ydot, psi0, zeta0) nodes), so that the panel can
show any state's viable actions without a second request: 120² x 40² pairs are 2.9 MB of bits.
"""

from __future__ import annotations

import base64

import numpy as np

from backend.services.presets import resolve_model
from backend.services.quick_calls import gait_not_found_as_parameter_error
from sim_core.model.controls import ControlSchedule
from sim_core.model.params import ModelParams


def section_study(spec, model: ModelParams, progress) -> dict:
    """An MFPT (of a gait or a controller) or viability job's computation; its JSON result."""
    if spec.kind == "viability":
        return _viability(spec, model, progress)
    if spec.kind == "loop-mfpt":
        return _loop_mfpt(spec, model, progress)
    return _mfpt(spec, model, progress)


def _mfpt(spec, model: ModelParams, progress) -> dict:
    """``parkour mfpt --json`` of the job's controls, noise and grid (both grids in-process: the
    chain's two solves are one computation, its progress by chunks of pairs)."""
    from backend.schemas.job_budget import mfpt_grid_of
    from sim_core.model.controls import LegControl
    from sim_core.robustness.mfpt import check_chain_inputs, mfpt
    from sim_core.section.gait_search import gait_of

    noise = spec.noise.model()
    check_chain_inputs(model, noise)
    controls = LegControl.from_degrees(spec.psi0_deg, spec.zeta0)
    if spec.start is not None:
        start = (spec.start.xdot, spec.start.ydot)
    else:
        guess = None if spec.guess is None else (spec.guess.xdot, spec.guess.ydot)
        with gait_not_found_as_parameter_error():
            start = gait_of(model, ControlSchedule((controls,)), guess=guess).state
    return mfpt(model, controls, noise, start=start, grid=mfpt_grid_of(spec), progress=progress).to_dict()


def _loop_mfpt(spec, model: ModelParams, progress) -> dict:
    """``parkour mfpt --controller --json`` of the job's law, target, climb, noise and splitting."""
    from experiments.loop_mfpt import Config, run
    from sim_core.robustness.splitting import SplittingOptions

    leg_length = resolve_model(None, spec.model.preset).robot.leg_length  # a stored preset is resolved already
    options = SplittingOptions(replicas=spec.replicas, runs=spec.runs, seed=spec.seed)
    config = Config(controller=spec.controller, target_m=spec.target_m, psi0_deg=spec.psi0_deg,
                    start_zeta0=spec.start_zeta0, noise=spec.noise.model(), options=options)  # fmt: skip
    return run(model, leg_length, config, progress=progress)


def _viability(spec, model: ModelParams, progress) -> dict:
    """The kernel and measure over the job's grid, and every viable pair as bits."""
    from sim_core.viability.engine import compute_viability
    from sim_core.viability.grid import section_grid
    from sim_core.viability.step_map import section_step_map

    grid = section_grid(
        states=spec.states,
        actions=spec.actions,
        psi0_deg_range=(spec.psi0_low_deg, spec.psi0_high_deg),
        zeta0_range=(spec.zeta0_low, spec.zeta0_high),
    )
    result = compute_viability(section_step_map(model), grid, progress=progress)
    xdot, ydot = grid.state_axes
    psi0, zeta0 = grid.action_axes
    return {
        **result.to_dict(),
        "state_axes": {"xdot": xdot.tolist(), "ydot": ydot.tolist()},
        "action_axes": {"psi0_deg": np.degrees(psi0).tolist(), "zeta0": zeta0.tolist()},
        "viable_pairs": base64.b64encode(np.packbits(result.viable_pairs.ravel())).decode("ascii"),
        "viable_pairs_shape": list(result.viable_pairs.shape),
    }
