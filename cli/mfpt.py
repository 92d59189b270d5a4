"""``parkour mfpt``: mean first-passage time of a noisy gait, from a Markov chain on the section."""

from __future__ import annotations

from typing import Annotated

import typer

from cli.options import (
    ControlsOption,
    GuessOption,
    JsonOption,
    ModelSetup,
    handles_errors,
    option_named,
    parse_controls,
    print_json,
    progress_bar,
    with_model,
    with_noise,
)
from sim_core.mfpt_grid import ChainGrid
from sim_core.noise import NoiseModel
from sim_core.validation import ParameterError

app = typer.Typer(rich_markup_mode=None)
DEFAULT_GRID = ChainGrid()


@app.command("mfpt")
@handles_errors
@with_model
@with_noise
def mfpt_command(
    setup: ModelSetup,
    noise: NoiseModel,
    controls: ControlsOption = "30:0.9",
    grid: Annotated[
        int, typer.Option("--grid", help="Velocity nodes per axis over where the noisy paths go (4-400).")
    ] = DEFAULT_GRID.velocity_nodes,
    pitch_spacing: Annotated[
        float, typer.Option("--pitch-spacing", help="Pitch nodes' spacing, in pitch-step standard deviations.")
    ] = DEFAULT_GRID.pitch_spacing,
    start: Annotated[
        tuple[float, float] | None,
        typer.Option("--start", help="Touchdown state XDOT YDOT to start from; default: the gait's fixed point."),
    ] = None,
    guess: GuessOption = None,
    as_json: JsonOption = False,
) -> None:
    """Mean jumps to failure from a Markov chain on (xdot, ydot, pitch): where Monte-Carlo saturates too."""
    from sim_core.controls import ControlSchedule
    from sim_core.gait_search import gait_of
    from sim_core.mfpt import check_chain_inputs, mfpt

    schedule = parse_controls(controls)
    if len(schedule) != 1:
        raise ParameterError("--controls", f"the chain takes one symmetric PSI0:ZETA0 pair, got {controls!r}")
    with option_named("--grid", "grid.velocity_nodes"), option_named("--pitch-spacing", "grid.pitch_spacing"):
        chain_grid = ChainGrid(velocity_nodes=grid, pitch_spacing=pitch_spacing)
    with (
        option_named("--asymmetry-psi0", "noise.asymmetry_psi0_deg"),
        option_named("--asymmetry-zeta0", "noise.asymmetry_zeta0"),
    ):
        check_chain_inputs(setup.model, noise)
    if start is None:
        start = gait_of(setup.model, ControlSchedule(schedule.legs), guess=guess).state
    with progress_bar(f"MFPT: chains of {grid} and fewer velocity nodes") as bar:
        result = mfpt(setup.model, schedule.legs[0], noise, start=start, grid=chain_grid, progress=bar)
    if as_json:
        print_json(result.to_dict())
        return
    from rich.console import Console
    from rich.table import Table

    table = Table("grid", "MFPT [jumps]", "λ₂", "1/(1-λ₂)", "cells", "seconds", title=f"MFPT, controls {controls}")
    for estimate in result.estimates:
        lambda_jumps = 1.0 / (1.0 - estimate.lambda2) if estimate.lambda2 < 1.0 else float("inf")
        table.add_row(
            f"{estimate.grid.velocity_nodes} nodes, pitch {estimate.grid.pitch_spacing:.2f} σ",
            f"{estimate.mfpt_jumps:.4g}",
            f"{estimate.lambda2:.6f}",
            f"{lambda_jumps:.4g}",
            f"{estimate.states:,}",
            f"{estimate.seconds:.1f}",
        )
    Console().print(table)
    print(f"MFPT {result.mfpt_jumps:.4g} jumps, discretisation error {result.discretisation_error:.1%}")
