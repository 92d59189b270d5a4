"""``parkour map`` and ``parkour trajectory``: run the model from a section state."""

from __future__ import annotations

import csv
import json
from dataclasses import asdict
from pathlib import Path
from typing import Annotated, Literal

import typer

from cli.options import (
    ControlsOption,
    JsonOption,
    ModelSetup,
    handles_errors,
    json_safe,
    note,
    parse_controls,
    print_json,
    with_model,
)
from sim_core.model.errors import ParameterError

app = typer.Typer(rich_markup_mode=None)

StateOption = Annotated[
    tuple[float, float],
    typer.Option(
        "--state",
        help="Section state XDOT YDOT at touchdown [sqrt(g l0)]; xdot < 0 (flying toward the left wall).",
    ),
]
JumpsOption = Annotated[int, typer.Option("--jumps", help="Number of jumps.", min=0, max=1_000_000)]


@app.command("map")
@handles_errors
@with_model
def map_command(
    state: StateOption,
    setup: ModelSetup,
    controls: ControlsOption = "30:0.9",
    jumps: JumpsOption = 10,
    as_json: JsonOption = False,
) -> None:
    """Apply the Poincaré map JUMPS times: section states and height gain per jump."""
    from sim_core.model.poincare import iterate_map

    orbit = iterate_map(setup.model, parse_controls(controls), state, jumps)
    if as_json:
        print_json(orbit.to_dict())
        return
    from rich.console import Console
    from rich.table import Table

    table = Table("jump", "xdot", "ydot", "rise (l0)", title=f"Poincaré map, controls {controls}")
    table.add_row("0", f"{orbit.states[0, 0]:.9f}", f"{orbit.states[0, 1]:.9f}", "")
    for k, rise in enumerate(orbit.rises, start=1):
        table.add_row(str(k), f"{orbit.states[k, 0]:.9f}", f"{orbit.states[k, 1]:.9f}", f"{rise:+.6f}")
    console = Console()
    console.print(table)
    if orbit.failure is not None:
        console.print(f"failed at jump {orbit.failed_jump}: {orbit.failure.code} — {orbit.failure.message}")


@app.command("trajectory")
@handles_errors
@with_model
def trajectory_command(
    out: Annotated[Path, typer.Option("--out", help="Output file, .csv or .json.")],
    setup: ModelSetup,
    controls: ControlsOption = "30:0.9",
    state: Annotated[
        tuple[float, float] | None,
        typer.Option("--state", help="Starting section state XDOT YDOT; default: the most stable gait found."),
    ] = None,
    jumps: JumpsOption = 10,
    rate: Annotated[
        float, typer.Option("--rate", help="Samples per unit time: per second with --units si, else per sqrt(l0/g).")
    ] = 100.0,
    units: Annotated[Literal["si", "nondimensional"], typer.Option("--units", help="Output units.")] = "si",
    as_json: JsonOption = False,
) -> None:
    """Sample the full path in wall coordinates (un-flipped) and write it to a file."""
    from sim_core.model.trajectory import simulate_trajectory

    if out.suffix not in (".csv", ".json"):
        raise ParameterError("out", f"must end in .csv or .json, got {out.name!r}")
    schedule = parse_controls(controls)
    if state is None:
        from sim_core.section.gait_search import gait_of

        gait = gait_of(setup.model, schedule)
        state = tuple(gait.state.tolist())
        note(f"starting on the {gait.motion} period-{gait.period} gait at state {list(state)}")
    sample_rate = rate * setup.robot.scales.time if units == "si" else rate
    trajectory = simulate_trajectory(setup.model, schedule, state, jumps, sample_rate=sample_rate)
    if units == "si":
        trajectory = trajectory.to_si(setup.robot)
    columns = trajectory.columns()
    if out.suffix == ".csv":
        with out.open("w", newline="") as handle:
            writer = csv.writer(handle)
            writer.writerow(trajectory.COLUMNS)
            writer.writerows(zip(*(column.tolist() for column in columns.values()), strict=True))
    else:
        document = {
            "units": trajectory.units,
            "controls": controls,
            "model": asdict(setup.model),
            "touchdown_times": trajectory.touchdown_times.tolist(),
            "rises": trajectory.rises.tolist(),
            "failure": None if trajectory.failure is None else trajectory.failure.code,
            "columns": {name: column.tolist() for name, column in columns.items()},
        }
        out.write_text(json.dumps(json_safe(document)))
    summary = {
        "out": str(out),
        "samples": int(trajectory.time.size),
        "jumps_completed": int(trajectory.rises.size),
        "climb": float(trajectory.rises.sum()),
        "units": trajectory.units,
        "failure": None if trajectory.failure is None else trajectory.failure.code,
    }
    if as_json:
        print_json(summary)
    else:
        note(
            f"wrote {summary['samples']} samples of {summary['jumps_completed']} jumps to {out} "
            f"({trajectory.units}); climbed {summary['climb']:.4f}"
            + ("" if trajectory.failure is None else f"; failed: {trajectory.failure.code}")
        )
