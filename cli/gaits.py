"""``parkour fixed-point`` and ``parkour gaits``: periodic gaits and their stability."""

from __future__ import annotations

from typing import Annotated

import typer

from cli.options import (
    ControlsOption,
    GuessOption,
    JsonOption,
    ModelSetup,
    PeriodOption,
    handles_errors,
    parse_controls,
    print_json,
    with_model,
)

app = typer.Typer(rich_markup_mode=None)


@app.command("fixed-point")
@handles_errors
@with_model
def fixed_point_command(
    setup: ModelSetup,
    controls: ControlsOption = "30:0.9",
    period: PeriodOption = None,
    guess: GuessOption = None,
    as_json: JsonOption = False,
) -> None:
    """Find a period-n fixed point, its eigenvalues, stability and climb per period."""
    from sim_core.section.gait_search import gait_of

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
    from sim_core.section.gait_search import search_gaits

    schedule = parse_controls(controls)
    period = period or len(schedule)
    gaits = search_gaits(setup.model, schedule, period, grid=(grid, grid))
    if as_json:
        print_json({"gaits": [gait.to_dict() for gait in gaits]})
    elif gaits:
        _print_gaits(gaits, f"Period-{period} gaits, controls {controls}")
    else:
        typer.echo(f"no period-{period} gait found from a {grid}x{grid} grid of guesses")


def _print_gaits(gaits: list, title: str) -> None:
    """A table of gaits (``sim_core.FixedPoint``) for people."""
    from rich.console import Console
    from rich.table import Table

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
