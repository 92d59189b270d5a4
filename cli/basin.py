"""``parkour basin``: the basin of attraction of a gait over a grid of section states."""

from __future__ import annotations

from typing import Annotated

import typer

from cli.options import (
    ControlsOption,
    GuessOption,
    JsonOption,
    ModelSetup,
    PeriodOption,
    SchedulerOption,
    handles_errors,
    option_named,
    parse_controls,
    print_json,
    progress_bar,
    with_model,
)
from sim_core.basins.grid import DEFAULT_JUMPS, DEFAULT_TOLERANCE

app = typer.Typer(rich_markup_mode=None)


@app.command("basin")
@handles_errors
@with_model
def basin_command(
    setup: ModelSetup,
    controls: ControlsOption = "30:0.9",
    period: PeriodOption = None,
    guess: GuessOption = None,
    grid: Annotated[int, typer.Option("--grid", help="Cells per axis.")] = 100,
    jumps: Annotated[int, typer.Option("--jumps", help="Jumps allowed to converge (the first cap).")] = DEFAULT_JUMPS,
    jump_limit: Annotated[
        int | None,
        typer.Option(
            "--jump-limit",
            help="Continue the cells still undecided after --jumps, doubling the cap each round, up to this many "
            "jumps in all. Default: no continuation.",
        ),
    ] = None,
    xdot_range: Annotated[
        tuple[float, float] | None,
        typer.Option("--xdot-range", help="LOW HIGH of xdot [sqrt(g l0)], below 0; default: gait ±1.5."),
    ] = None,
    ydot_range: Annotated[
        tuple[float, float] | None,
        typer.Option("--ydot-range", help="LOW HIGH of ydot [sqrt(g l0)]; default: gait ±1.5."),
    ] = None,
    tolerance: Annotated[
        float, typer.Option("--tolerance", help="Distance to the gait's orbit that counts as converged.")
    ] = DEFAULT_TOLERANCE,
    summary: Annotated[bool, typer.Option("--summary", help="With --json: leave out the per-cell grids.")] = False,
    scheduler: SchedulerOption = None,
    as_json: JsonOption = False,
) -> None:
    """Basin of attraction of a gait over a grid of section states (xdot, ydot)."""
    from experiments.cluster import chunk_map_for, scheduler_address
    from experiments.gait_basin import gait_basin

    schedule = parse_controls(controls)
    with (
        option_named("--jump-limit", "jump_limit"),
        chunk_map_for(scheduler_address(scheduler)) as chunk_map,
        progress_bar(f"basin: {grid}x{grid} cells") as bar,
    ):
        basin = gait_basin(
            setup.model,
            schedule,
            period=period,
            guess=guess,
            grid=grid,
            xdot_range=xdot_range,
            ydot_range=ydot_range,
            max_jumps=jumps,
            tolerance=tolerance,
            jump_limit=jump_limit,
            chunk_map=chunk_map,
            progress=bar,
        )
    gait, cells = basin.gait, basin.grid
    if as_json:
        print_json(basin.to_dict(include_grids=not summary))
        return
    from rich.console import Console
    from rich.table import Table

    table = Table("measure", "value", title=f"Basin of the period-{gait.period} gait, controls {controls}")
    table.add_row("gait state", f"({gait.state[0]:.5f}, {gait.state[1]:.5f}), max |λ| {gait.max_abs_eigenvalue:.4f}")
    table.add_row("xdot range", f"{cells.xdot_range[0]:.3f} … {cells.xdot_range[1]:.3f}")
    table.add_row("ydot range", f"{cells.ydot_range[0]:.3f} … {cells.ydot_range[1]:.3f}")
    limit = "" if basin.jump_limit == jumps else f", undecided cells continued up to {basin.jump_limit}"
    table.add_row("grid", f"{grid} x {grid}, {jumps} jumps{limit}, tolerance {tolerance:g}")
    table.add_row("area (g l0)", f"{basin.area:.4f} ({basin.fraction:.1%} of the window)")
    if limit:
        rounds = (f"{r['cap']}: {r['converged']:,} in, {r['undecided']:,} undecided" for r in basin.rounds())
        table.add_row("by cap (jumps)", "; ".join(rounds))
    for outcome, count in basin.outcome_counts().items():
        if count:
            table.add_row(f"  {outcome}", f"{count:,} cells")
    Console().print(table)
