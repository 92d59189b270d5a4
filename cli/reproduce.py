"""``parkour reproduce``: the paper's figures, their data and a paper-vs-ours report."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from cli.options import (
    JsonOption,
    ModelSetup,
    SchedulerOption,
    handles_errors,
    note,
    print_json,
    progress_bar,
    with_model,
)
from experiments.reproduce import FIGURES, figure_names

app = typer.Typer(rich_markup_mode=None)


@app.command("reproduce")
@handles_errors
@with_model
def reproduce_command(
    setup: ModelSetup,
    figures: Annotated[list[str], typer.Argument(help=f"Figures: {', '.join(FIGURES)} or all.", show_default=False)],
    out: Annotated[Path, typer.Option("--out", help="Directory for the figures, data and report.md.")],
    quick: Annotated[
        bool, typer.Option("--quick", help="Coarse configurations (seconds, for smoke tests); marked in the report.")
    ] = False,
    scheduler: SchedulerOption = None,
    as_json: JsonOption = False,
) -> None:
    """Regenerate paper figures: PNG + SVG, CSV + JSON data, and report.md (paper vs ours)."""
    from experiments.cluster import chunk_map_for, scheduler_address
    from experiments.reproduce import reproduce

    names = figure_names(figures)
    with chunk_map_for(scheduler_address(scheduler)) as chunk_map, progress_bar("reproduce") as progress:
        written = reproduce(
            names,
            out,
            setup.robot,
            quick=quick,
            chunk_map=chunk_map,
            progress=lambda name, done, total: progress(done, total, description=f"reproduce {name}"),
        )
    if as_json:
        print_json({"out": str(out), "figures": names, "files": [str(path) for path in written]})
        return
    for path in written:
        typer.echo(str(path))
    note(f"report: {out / 'report.md'}")
