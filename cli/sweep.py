"""``parkour sweep``: a gait followed over zeta0 — stability, climb, basin area, jumping in place."""

from __future__ import annotations

from typing import Annotated

import typer

from cli.options import (
    GuessOption,
    JsonOption,
    ModelSetup,
    SchedulerOption,
    handles_errors,
    option_named,
    print_json,
    with_model,
)
from cli.studies import fixed_leg_of, over_zeta0
from sim_core.basins.grid import DEFAULT_BASIN_WINDOW, DEFAULT_JUMPS, DEFAULT_TOLERANCE, BasinGrid

app = typer.Typer(rich_markup_mode=None)


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
    basin_jumps: Annotated[
        int, typer.Option("--basin-jumps", help="Jumps allowed to converge (the first cap).")
    ] = DEFAULT_JUMPS,
    basin_jump_limit: Annotated[
        int | None,
        typer.Option(
            "--basin-jump-limit",
            help="Continue the basin cells still undecided after --basin-jumps, doubling the cap, up to this many "
            "jumps in all. Default: no continuation.",
        ),
    ] = None,
    scheduler: SchedulerOption = None,
    as_json: JsonOption = False,
) -> None:
    """Follow a gait over zeta0: max |λ|, climb, basin area, and the zeta0 of jumping in place."""
    from sim_core.basins.basin import check_convergence_test
    from sim_core.basins.sweep import energy_sweep, zeta0_values

    zeta0s = zeta0_values(*zeta0_range, steps)
    fixed = fixed_leg_of(fixed_leg)
    with option_named("--basin-grid", "grid"):
        grid = None if basin_grid == 0 else BasinGrid(*DEFAULT_BASIN_WINDOW, basin_grid)
    with option_named("--basin-jump-limit", "jump_limit"):
        check_convergence_test(basin_jumps, DEFAULT_TOLERANCE, basin_jump_limit)
    sweep = over_zeta0(
        energy_sweep,
        f"sweeping {steps} zeta0 values",
        scheduler,
        setup,
        psi0,
        zeta0s,
        fixed,
        guess,
        basin_grid=grid,
        basin_jumps=basin_jumps,
        basin_jump_limit=basin_jump_limit,
    )
    if as_json:
        print_json(sweep.to_dict())
        return
    from rich.console import Console
    from rich.table import Table

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
