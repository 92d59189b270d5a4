"""``parkour serve``: the service — REST API, experiment store and batch jobs."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from backend.cli.options import handles_errors, note
from backend.settings import DEFAULT_HOST, DEFAULT_PORT, Settings

app = typer.Typer(rich_markup_mode=None)


@app.command("serve")
@handles_errors
def serve_command(
    data_dir: Annotated[
        Path | None,
        typer.Option("--data-dir", help="Where the database and token live; default $PARKOUR_DATA_DIR or ./data."),
    ] = None,
    host: Annotated[
        str, typer.Option("--host", help="Interface to bind; 0.0.0.0 exposes it to the network.")
    ] = DEFAULT_HOST,
    port: Annotated[int, typer.Option("--port", help="TCP port.", min=1, max=65535)] = DEFAULT_PORT,
) -> None:
    """Start the service (SQLite in the data directory unless DATABASE_URL says otherwise)."""
    import uvicorn

    from backend.api.app import api_token, create_app

    settings = Settings.from_environment(data_dir)
    token, created = api_token(settings.data_dir)
    application = create_app(settings)
    base = f"http://{host}:{port}"
    note(f"ParkourLab on {base}/  (API docs: {base}/docs)")
    note(f"data: {settings.data_dir}  database: {settings.database_url.split('://')[0]}")
    if created:
        note(f"API token for changes (shown once; kept in {settings.data_dir / 'api_token'}): {token}")
    uvicorn.run(application, host=host, port=port, log_level="info")
