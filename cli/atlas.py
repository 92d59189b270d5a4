"""``parkour atlas``: where stable gaits live over a grid of controls."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import numpy as np
import typer

from cli.options import (
    JsonOption,
    ModelSetup,
    SchedulerOption,
    handles_errors,
    note,
    option_named,
    print_json,
    with_model,
)
from cli.studies import run_study
from sim_core.model.controls import ControlSchedule
from sim_core.model.errors import ParameterError
from sim_core.model.validation import check_range

app = typer.Typer(rich_markup_mode=None)


@app.command("atlas")
@handles_errors
@with_model
def atlas_command(
    setup: ModelSetup,
    psi0_range: Annotated[
        tuple[float, float], typer.Option("--psi0-range", help="LOW HIGH of psi0 [degrees] (symmetric atlas).")
    ] = (15.0, 45.0),
    zeta0_range: Annotated[tuple[float, float], typer.Option("--zeta0-range", help="LOW HIGH of zeta0.")] = (
        0.80,
        0.98,
    ),
    grid: Annotated[tuple[int, int], typer.Option("--grid", help="ROWS COLUMNS of the atlas.")] = (13, 19),
    pair: Annotated[
        tuple[float, float] | None,
        typer.Option(
            "--pair", help="PSI0_L PSI0_R [degrees]: an L/R atlas over zeta0_L (rows) x zeta0_R (columns) instead."
        ),
    ] = None,
    transient: Annotated[int, typer.Option("--transient", help="Jumps to let each orbit settle.")] = 300,
    plot: Annotated[Path | None, typer.Option("--plot", help="Also draw the map to this .png or .svg file.")] = None,
    scheduler: SchedulerOption = None,
    as_json: JsonOption = False,
) -> None:
    """Where stable gaits live over a grid of controls: period and climb of the most stable gait."""
    from sim_core.basins.sweep import zeta0_values
    from sim_core.model.poincare import check_jumps
    from sim_core.section.atlas import gait_atlas

    rows_count, columns_count = grid
    if plot is not None and plot.suffix not in (".png", ".svg"):
        raise ParameterError("plot", f"must end in .png or .svg, got {plot.name!r}")
    with option_named("--grid COLUMNS", "steps"):
        columns = zeta0_values(*zeta0_range, columns_count)
    if pair is None:
        rows = _degrees_values("psi0_range", psi0_range, rows_count)
        schedules = [ControlSchedule.from_degrees([(psi0, zeta0)]) for psi0 in rows for zeta0 in columns]
        labels = ("psi0 [deg]", "zeta0 [l0]")
    else:
        with option_named("--grid ROWS", "steps"):
            rows = zeta0_values(*zeta0_range, rows_count)
        schedules = [
            ControlSchedule.from_degrees([(pair[0], zeta0_left), (pair[1], zeta0_right)])
            for zeta0_left in rows
            for zeta0_right in columns
        ]
        labels = (f"zeta0_L [l0] (psi0_L {pair[0]:g}°)", f"zeta0_R [l0] (psi0_R {pair[1]:g}°)")
    check_jumps(transient)
    atlas = run_study(
        gait_atlas,
        f"atlas: {rows_count}x{columns_count} cells",
        scheduler,
        setup.model,
        schedules,
        rows,
        columns,
        row_label=labels[0],
        column_label=labels[1],
        transient_jumps=transient,
    )
    if plot is not None:
        from experiments.atlas_map import save_atlas

        save_atlas(atlas, plot, "Gait atlas" + ("" if pair is None else f", psi0 {pair[0]:g}°/{pair[1]:g}°"))
        note(f"atlas map: {plot}")
    if as_json:
        print_json(atlas.to_dict())
        return
    counts = atlas.count
    climbing = np.nansum(atlas.climb_per_jump > 0)
    typer.echo(
        f"{counts.size} cells: {int(np.count_nonzero(counts))} with a stable gait, {int(climbing)} climbing; "
        f"periods found: {sorted(set(atlas.period[counts > 0].tolist())) or 'none'}"
    )


def _degrees_values(field: str, interval: tuple[float, float], count: int) -> np.ndarray:
    low, high = (check_range(field, value, 0.0, 90.0) for value in interval)
    if not low < high:
        raise ParameterError(field, f"must be a non-empty interval with low < high, got [{low:g}, {high:g}]")
    if not 2 <= count <= 1000:
        raise ParameterError("--grid ROWS", f"must be an integer in [2, 1000], got {count}")
    return np.linspace(low, high, count)
