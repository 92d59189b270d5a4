"""``parkour basin``: studies over many start states (issue 4)."""

from __future__ import annotations

from typing import Annotated

import typer
from rich.console import Console
from rich.table import Table

from backend.cli.options import (
    ControlsOption,
    JsonOption,
    ModelSetup,
    default_gait,
    handles_errors,
    parse_controls,
    print_json,
    with_model,
)
from sim_core import find_fixed_point
from sim_core.basin import DEFAULT_JUMPS, DEFAULT_TOLERANCE, BasinGrid, check_convergence_test, compute_basin

app = typer.Typer(rich_markup_mode=None)

PeriodOption = Annotated[
    int | None, typer.Option("--period", help="Period n of the gait in jumps; a multiple of the schedule length.")
]
GuessOption = Annotated[
    tuple[float, float] | None,
    typer.Option("--guess", help="Initial guess XDOT YDOT for the gait; default: the most stable one a search finds."),
]


@app.command("basin")
@handles_errors
@with_model
def basin_command(
    setup: ModelSetup,
    controls: ControlsOption = "30:0.9",
    period: PeriodOption = None,
    guess: GuessOption = None,
    grid: Annotated[int, typer.Option("--grid", help="Cells per axis.")] = 100,
    jumps: Annotated[int, typer.Option("--jumps", help="Jumps allowed to converge.")] = DEFAULT_JUMPS,
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
    as_json: JsonOption = False,
) -> None:
    """Basin of attraction of a gait over a grid of section states (xdot, ydot)."""
    schedule = parse_controls(controls)
    period = period or len(schedule)
    # The whole spec is checked before the (slow) gait search; placeholders stand in for default ranges.
    BasinGrid(xdot_range or (-2.0, -1.0), ydot_range or (-1.0, 1.0), grid)
    check_convergence_test(jumps, tolerance)
    gait = (
        default_gait(setup.model, schedule, period)
        if guess is None
        else find_fixed_point(setup.model, schedule, period, guess)
    )
    default = BasinGrid.around(gait.state, grid)
    cells = BasinGrid(xdot_range or default.xdot_range, ydot_range or default.ydot_range, grid)
    basin = compute_basin(setup.model, schedule, gait, cells, max_jumps=jumps, tolerance=tolerance)
    if as_json:
        print_json(basin.to_dict(include_grids=not summary))
        return
    table = Table("measure", "value", title=f"Basin of the period-{gait.period} gait, controls {controls}")
    table.add_row("gait state", f"({gait.state[0]:.5f}, {gait.state[1]:.5f}), max |λ| {gait.max_abs_eigenvalue:.4f}")
    table.add_row("xdot range", f"{cells.xdot_range[0]:.3f} … {cells.xdot_range[1]:.3f}")
    table.add_row("ydot range", f"{cells.ydot_range[0]:.3f} … {cells.ydot_range[1]:.3f}")
    table.add_row("grid", f"{grid} x {grid}, {jumps} jumps, tolerance {tolerance:g}")
    table.add_row("area (g l0)", f"{basin.area:.4f} ({basin.fraction:.1%} of the window)")
    for outcome, count in basin.outcome_counts().items():
        if count:
            table.add_row(f"  {outcome}", f"{count:,} cells")
    Console().print(table)
