"""``parkour mfpt``: mean first-passage time of a noisy gait, from a Markov chain on the section, or
of a closed-loop controller (``--controller``), by splitting on its compiled loop."""

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
    refuse_given,
    with_model,
    with_noise,
)
from sim_core.control.registry import NAMES
from sim_core.model.noise import NoiseModel
from sim_core.model.validation import ParameterError
from sim_core.robustness.mfpt_grid import ChainGrid

app = typer.Typer(rich_markup_mode=None)
DEFAULT_GRID = ChainGrid()
GAIT_CONTROLS, CLIMB_CONTROLS = "30:0.9", "35:0.9"
DEFAULT_TARGET_M = 0.55


@app.command("mfpt")
@handles_errors
@with_model
@with_noise
def mfpt_command(
    setup: ModelSetup,
    noise: NoiseModel,
    controls: ControlsOption = None,
    grid: Annotated[
        int | None,
        typer.Option(
            "--grid",
            help=f"Velocity nodes per axis where the noisy paths go (4-400; default {DEFAULT_GRID.velocity_nodes}).",
        ),
    ] = None,
    pitch_spacing: Annotated[
        float | None,
        typer.Option(
            "--pitch-spacing",
            help=f"Pitch nodes' spacing, in pitch-step standard deviations (default {DEFAULT_GRID.pitch_spacing:g}).",
        ),
    ] = None,
    start: Annotated[
        tuple[float, float] | None,
        typer.Option("--start", help="Touchdown state XDOT YDOT to start from; default: the gait's fixed point."),
    ] = None,
    guess: GuessOption = None,
    no_cache: Annotated[
        bool, typer.Option("--no-cache", help="Build both chains, neither loading nor storing cached ones.")
    ] = False,
    controller: Annotated[
        str | None,
        typer.Option(
            "--controller",
            help=f"A closed-loop law ({', '.join(NAMES)}): its MFPT by splitting on the compiled loop, no pitch "
            f"drift; --controls then gives the climb's nominal psi0 and first zeta0 (default {CLIMB_CONTROLS}).",
        ),
    ] = None,
    target: Annotated[
        float | None,
        typer.Option("--target", help=f"Height the law holds [m] (with --controller; default {DEFAULT_TARGET_M:g})."),
    ] = None,
    replicas: Annotated[
        int | None, typer.Option("--replicas", help="Splitting: replicas per run (with --controller; default 100).")
    ] = None,
    runs: Annotated[
        int | None, typer.Option("--runs", help="Splitting: independent runs, for the interval (default 64).")
    ] = None,
    seed: Annotated[int | None, typer.Option("--seed", help="Splitting: the seed of every draw (default 0).")] = None,
    as_json: JsonOption = False,
) -> None:
    """Mean jumps to failure where Monte-Carlo saturates: of fixed controls from a Markov chain on
    (xdot, ydot, pitch), or of a controller holding a height (--controller) by splitting."""
    if controller is not None:
        given = {"--grid": grid, "--pitch-spacing": pitch_spacing, "--start": start, "--guess": guess}
        refuse_given(
            given | {"--no-cache": no_cache or None}, "applies to the chain of fixed controls, not with --controller"
        )
        from cli.mfpt_loop import controller_mfpt

        splitting = {"replicas": replicas, "runs": runs, "seed": seed}
        controller_mfpt(setup, noise, controller, controls or CLIMB_CONTROLS, target, splitting, as_json)
        return
    refuse_given({"--target": target, "--replicas": replicas, "--runs": runs, "--seed": seed}, "needs --controller")
    _chain_mfpt(setup, noise, controls or GAIT_CONTROLS, grid, pitch_spacing, start, guess, no_cache, as_json)


def _chain_mfpt(setup, noise, controls, grid, pitch_spacing, start, guess, no_cache, as_json) -> None:
    from sim_core.model.controls import ControlSchedule
    from sim_core.robustness.mfpt import check_chain_inputs, mfpt
    from sim_core.section.gait_search import gait_of

    schedule = parse_controls(controls)
    if len(schedule) != 1:
        raise ParameterError("--controls", f"the chain takes one symmetric PSI0:ZETA0 pair, got {controls!r}")
    grid = DEFAULT_GRID.velocity_nodes if grid is None else grid
    pitch_spacing = DEFAULT_GRID.pitch_spacing if pitch_spacing is None else pitch_spacing
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
        result = mfpt(
            setup.model, schedule.legs[0], noise, start=start, grid=chain_grid, progress=bar, cache=not no_cache
        )
    if as_json:
        print_json({**result.to_dict(), "method": "chain"})
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
