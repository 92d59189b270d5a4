"""``parkour export``: a stored run — robot, replay, or simulated with its path — as an MCAP recording,
which Foxglove and Rerun open (the format: docs/service.md, "Recordings"; the writers:
backend/services/mcap_export.py, a simulation's backend/services/mcap_sim.py)."""

from __future__ import annotations

import io
from pathlib import Path
from typing import Annotated

import typer

from cli.options import DataDirOption, JsonOption, handles_errors, note, print_json, store_sessions
from sim_core.model.errors import ParameterError

app = typer.Typer(rich_markup_mode=None)


@app.command("export")
@handles_errors
def export_command(
    run_id: Annotated[int, typer.Argument(help="The run's id (a robot, replay or simulated run).", min=1)],
    out: Annotated[
        Path | None, typer.Option("--out", help="The MCAP file to write; default parkourlab-run-RUN_ID.mcap.")
    ] = None,
    data_dir: DataDirOption = None,
    json_output: JsonOption = False,
) -> None:
    """Export a run as MCAP: a robot or replay run's tracker poses, touchdowns, commands, telemetry and the model's
    prediction; a simulated run's path (stored with trajectory_rate) and touchdowns on the same channels."""
    from backend.errors import Conflict, NotFound
    from backend.services import mcap_export

    stream = io.BytesIO()
    with store_sessions(data_dir) as sessions, sessions() as session:
        try:
            counts = mcap_export.export_run(session, run_id, stream)
        except (NotFound, Conflict) as error:
            raise ParameterError("run_id", str(error)) from None
    path = out or Path(f"parkourlab-run-{run_id}.mcap")
    path.write_bytes(stream.getvalue())
    size = path.stat().st_size
    if json_output:
        print_json({"path": str(path), "bytes": size, "channels": counts})
    else:
        note(f"run {run_id} → {path} ({size} bytes): " + ", ".join(f"{topic} {n}" for topic, n in counts.items()))
