"""How the study commands run: on a Dask cluster or in-process, with a progress bar, over zeta0."""

from __future__ import annotations

from collections.abc import Callable

from cli.options import ModelSetup, parse_controls, progress_bar
from sim_core.model.controls import LegControl
from sim_core.model.errors import ParameterError


def run_study(study: Callable, description: str, scheduler: str | None, *args, **kwargs):
    """``study(*args, **kwargs, chunk_map=..., progress=...)``: on the Dask cluster ``scheduler``
    names (else in-process), with a progress bar labelled ``description``."""
    from experiments.cluster import chunk_map_for, scheduler_address

    with (
        chunk_map_for(scheduler_address(scheduler)) as chunk_map,
        progress_bar(description) as progress,
    ):
        return study(*args, chunk_map=chunk_map, progress=progress, **kwargs)


def over_zeta0(
    study: Callable,
    description: str,
    scheduler: str | None,
    setup: ModelSetup,
    psi0_deg: float,
    zeta0s,
    fixed_leg: LegControl | None,
    guess,
    **options,
):
    """A study of the gait over zeta0 values (sweep, MJTF): ``study(model, psi0 [rad], zeta0s, ...)``
    with one leg ``fixed_leg`` held (None: both legs swept) and the first gait from ``guess``."""
    psi0 = LegControl.from_degrees(psi0_deg, zeta0s[0]).psi0
    return run_study(
        study, description, scheduler, setup.model, psi0, zeta0s, fixed_leg=fixed_leg, guess=guess, **options
    )


def fixed_leg_of(text: str | None) -> LegControl | None:
    """``--fixed-leg PSI0:ZETA0``: the leg held fixed while the other sweeps (None: both sweep)."""
    if text is None:
        return None
    schedule = parse_controls(text)
    if len(schedule) != 1:
        raise ParameterError("fixed_leg", f"must be one PSI0:ZETA0 pair, got {text!r}")
    return schedule[0]
