"""``parkour fixed-point`` and ``parkour gaits``: periodic gaits and their stability."""

from __future__ import annotations

from typing import Annotated

import typer
from rich.console import Console
from rich.table import Table

from cli.options import (
    ControlsOption,
    JsonOption,
    ModelSetup,
    handles_errors,
    parse_controls,
    print_json,
    with_model,
)
from sim_core import FixedPoint

app = typer.Typer(rich_markup_mode=None)

PeriodOption = Annotated[
    int | None, typer.Option("--period", help="Period n in jumps; a multiple of the schedule length (default: it).")
]


@app.command("fixed-point")
@handles_errors
@with_model
def fixed_point_command(
    setup: ModelSetup,
    controls: ControlsOption = "30:0.9",
    period: PeriodOption = None,
    guess: Annotated[
        tuple[float, float] | None,
        typer.Option("--guess", help="Initial guess XDOT YDOT for Levenberg–Marquardt; default: search a grid."),
    ] = None,
    as_json: JsonOption = False,
) -> None:
    """Find a period-n fixed point, its eigenvalues, stability and climb per period."""
    from sim_core.fixed_points import gait_of

    schedule = parse_controls(controls)
    gait = gait_of(setup.model, schedule, period or len(schedule), guess)
    if as_json:
        print_json(gait.to_dict())
    else:
        _print_gaits([gait], f"Fixed point, controls {controls}")


@app.command("gaits")
@handles_errors
@with_model
def gaits_command(
    setup: ModelSetup,
    controls: ControlsOption = "30:0.9",
    period: PeriodOption = None,
    grid: Annotated[int, typer.Option("--grid", help="Guesses per axis of the search grid.", min=1, max=50)] = 6,
    as_json: JsonOption = False,
) -> None:
    """Search a grid of guesses for distinct period-n gaits (climbing, in place, descending)."""
    from sim_core.fixed_points import search_gaits

    schedule = parse_controls(controls)
    period = period or len(schedule)
    gaits = search_gaits(setup.model, schedule, period, grid=(grid, grid))
    if as_json:
        print_json({"gaits": [gait.to_dict() for gait in gaits]})
    elif gaits:
        _print_gaits(gaits, f"Period-{period} gaits, controls {controls}")
    else:
        typer.echo(f"no period-{period} gait found from a {grid}x{grid} grid of guesses")


def _print_gaits(gaits: list[FixedPoint], title: str) -> None:
    table = Table("xdot", "ydot", "period", "max |λ|", "stable", "climb (l0)", "motion", title=title)
    for gait in gaits:
        table.add_row(
            f"{gait.state[0]:.6f}",
            f"{gait.state[1]:.6f}",
            str(gait.period),
            f"{gait.max_abs_eigenvalue:.4f}",
            "yes" if gait.stable else "no",
            f"{gait.climb_per_period:+.5f}",
            gait.motion,
        )
    Console().print(table)
