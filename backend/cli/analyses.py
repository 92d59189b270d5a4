"""``parkour basin`` and ``parkour sweep``: studies over many start states and controls (issue 4)."""

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
    progress_bar,
    with_model,
)
from sim_core import LegControl, ParameterError, find_fixed_point
from sim_core.basin import DEFAULT_JUMPS, DEFAULT_TOLERANCE, BasinGrid, check_convergence_test, compute_basin
from sim_core.sweep import DEFAULT_BASIN_WINDOW, energy_sweep, zeta0_values

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


@app.command("sweep")
@handles_errors
@with_model
def sweep_command(
    setup: ModelSetup,
    psi0: Annotated[float, typer.Option("--psi0", help="Angle of the swept leg(s) [degrees].")] = 30.0,
    zeta0_range: Annotated[
        tuple[float, float], typer.Option("--zeta0-range", help="LOW HIGH of the swept zeta0, in (0, 1).")
    ] = (0.80, 0.97),
    steps: Annotated[int, typer.Option("--steps", help="Number of zeta0 values.")] = 30,
    fixed_leg: Annotated[
        str | None,
        typer.Option("--fixed-leg", help="PSI0:ZETA0 of a leg held fixed (L); the other (R) sweeps. Default: both."),
    ] = None,
    guess: GuessOption = None,
    basin_grid: Annotated[
        int, typer.Option("--basin-grid", help="Cells per axis of each basin; 0 skips the basins.")
    ] = 40,
    basin_jumps: Annotated[int, typer.Option("--basin-jumps", help="Jumps allowed to converge.")] = DEFAULT_JUMPS,
    as_json: JsonOption = False,
) -> None:
    """Follow a gait over zeta0: max |λ|, climb, basin area, and the zeta0 of jumping in place."""
    zeta0s = zeta0_values(*zeta0_range, steps)
    fixed = None
    if fixed_leg is not None:
        schedule = parse_controls(fixed_leg)
        if len(schedule) != 1:
            raise ParameterError("fixed_leg", f"must be one PSI0:ZETA0 pair, got {fixed_leg!r}")
        fixed = schedule[0]
    grid = None if basin_grid == 0 else BasinGrid(*DEFAULT_BASIN_WINDOW, basin_grid)
    check_convergence_test(basin_jumps, DEFAULT_TOLERANCE)
    with progress_bar(f"sweeping {steps} zeta0 values") as progress:
        sweep = energy_sweep(
            setup.model,
            LegControl.from_degrees(psi0, zeta0s[0]).psi0,
            zeta0s,
            fixed_leg=fixed,
            guess=guess,
            basin_grid=grid,
            basin_jumps=basin_jumps,
            progress=progress,
        )
    if as_json:
        print_json(sweep.to_dict())
        return
    legs = f"psi0 {psi0:g}°" + ("" if fixed is None else f", fixed leg {fixed_leg}")
    table = Table("zeta0", "energy (m g l0)", "max |λ|", "stable", "climb/jump (l0)", "basin (g l0)", title=legs)
    for point in sweep.points:
        gait = point.gait
        if gait is None:
            table.add_row(f"{point.zeta0:.4f}", f"{point.energy:.3f}", "no gait found", "", "", "")
            continue
        table.add_row(
            f"{point.zeta0:.4f}",
            f"{point.energy:.3f}",
            f"{gait.max_abs_eigenvalue:.4f}",
            "yes" if gait.stable else "no",
            f"{point.climb_per_jump:+.4f}",
            "" if point.basin_area is None else f"{point.basin_area:.3f}",
        )
    Console().print(table)
    crossings = ", ".join(f"{z:.6f}" for z in sweep.in_place_zeta0) or "none in range"
    typer.echo(f"jumping in place at zeta0 = {crossings}")
