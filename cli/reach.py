"""``parkour reach``: over a grid of controls, how high a fixed schedule climbs a world and how
it ends (docs/model.md §8)."""

from __future__ import annotations

from typing import Annotated

import typer

from cli.options import JsonOption, ModelSetup, SchedulerOption, handles_errors, option_named, print_json, with_model
from cli.studies import run_study

app = typer.Typer(rich_markup_mode=None)


@app.command("reach")
@handles_errors
@with_model
def reach_command(
    world: Annotated[str, typer.Option("--world", help="A world file (.json) or a named world (parkour world list).")],
    state: Annotated[
        tuple[float, float],
        typer.Option("--state", help="The body's velocity XDOT YDOT at touchdown 0 [sqrt(g l0)], xdot < 0."),
    ],
    setup: ModelSetup,
    psi0_range: Annotated[
        tuple[float, float], typer.Option("--psi0-range", help="LOW HIGH of the grid's leg angles [deg].")
    ] = (20.0, 40.0),
    psi0_steps: Annotated[int, typer.Option("--psi0-steps", help="Leg angles in the grid.")] = 21,
    zeta0_range: Annotated[
        tuple[float, float], typer.Option("--zeta0-range", help="LOW HIGH of the grid's leg lengths [l0].")
    ] = (0.84, 0.96),
    zeta0_steps: Annotated[int, typer.Option("--zeta0-steps", help="Leg lengths in the grid.")] = 13,
    jumps: Annotated[int, typer.Option("--jumps", help="Most jumps per cell.", min=1, max=1_000_000)] = 40,
    foot_y: Annotated[float, typer.Option("--foot-y", help="Touchdown 0's foot height on the left side [l0].")] = 0.0,
    scheduler: SchedulerOption = None,
    as_json: JsonOption = False,
) -> None:
    """How high each symmetric schedule PSI0:ZETA0 of a grid climbs a world, and how it ends: at
    the world's top, at the jump cap, or by a failure (a failure map by code)."""
    from sim_core.world.named import resolve_world
    from sim_core.world.reach import grid_values, reach_map

    chosen, _description = resolve_world(world, setup.model.d_hat, setup.robot.scales.length)
    with option_named("--psi0-steps", "steps"):
        psi0s = grid_values(*psi0_range, psi0_steps)
    with option_named("--zeta0-steps", "steps"):
        zeta0s = grid_values(*zeta0_range, zeta0_steps)
    cells = f"{psi0s.size} x {zeta0s.size} cells"
    reach = run_study(reach_map, f"reach in {chosen.name}: {cells}", scheduler, setup.model, chosen, psi0s, zeta0s,
                      state, jumps, foot_y=foot_y)  # fmt: skip
    document = reach.to_dict() | {"l0_m": setup.robot.scales.length}
    if as_json:
        print_json(document)
        return
    from rich.console import Console
    from rich.table import Table

    best = reach.highest.argmax()
    row, column = divmod(int(best), reach.psi0_deg.size)
    title = f"reach in {chosen.name} ({cells}, up to {jumps} jumps, top {reach.top:.2f} l0)"
    table = Table("ending", "cells", title=title)
    for ending, count in reach.outcomes().items():
        if count:
            table.add_row(ending, str(count))
    console = Console()
    console.print(table)
    metres = reach.highest[row, column] * setup.robot.scales.length
    where = f"{reach.psi0_deg[column]:g}:{reach.zeta0[row]:g}"
    console.print(f"highest: {reach.highest[row, column]:.3f} l0 ({metres:.3f} m) at {where}, "
                  f"ending {reach.endings()[row, column]}")  # fmt: skip
