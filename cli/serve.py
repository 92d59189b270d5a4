"""``parkour serve``: the service — REST API, experiment store, batch jobs, the control panel and
the 3D view.

This is where the parts meet: the backend's FastAPI application, with the viser view built by
``frontend.viewer`` plugged in through ``create_app(view_factory=...)``.
"""

from __future__ import annotations

import gc
from typing import Annotated

import typer

from backend.settings import DEFAULT_HOST, DEFAULT_PORT, WILDCARD_ADDRESSES, Settings
from cli.options import EXIT_USAGE, DataDirOption, handles_errors, note

DEFAULT_VIEW_PORT = 8001
YOUNG_COLLECTION_THRESHOLD = 20_000  # allocations between young collections (CPython 3.11: 700)
GRACEFUL_SHUTDOWN_S = 10.0  # [s] a SIGTERM waits at most this long for responses still being sent

app = typer.Typer(rich_markup_mode=None)


@app.command("serve")
@handles_errors
def serve_command(
    data_dir: DataDirOption = None,
    host: Annotated[
        str,
        typer.Option(
            "--host",
            help="Interface to bind (the 3D view's too); 0.0.0.0 exposes them to the network. A name or address"
            " given here is also one the service answers to; add others with $PARKOUR_ALLOWED_HOSTS.",
        ),
    ] = DEFAULT_HOST,
    port: Annotated[
        int, typer.Option("--port", help="TCP port of the API and panel.", min=1, max=65535)
    ] = DEFAULT_PORT,
    view_port: Annotated[
        int,
        typer.Option(
            "--view-port",
            help="TCP port of the 3D view; the next free one if busy, any free one if 0.",
            min=0,
            max=65535,
        ),
    ] = DEFAULT_VIEW_PORT,
    view: Annotated[bool, typer.Option("--view/--no-view", help="Start the 3D view.")] = True,
) -> None:
    """Start the service (SQLite in the data directory unless DATABASE_URL says otherwise)."""
    import uvicorn

    from backend.api.app import create_app
    from backend.api.token_file import api_token
    from backend.store.drivers import StoreUnavailable, check_store

    try:
        settings = Settings.from_environment(data_dir, allowed_hosts=[host], listen_on=host)
        check_store(settings.database_url)
    except StoreUnavailable as error:
        typer.echo(f"error: {error}", err=True)
        raise typer.Exit(EXIT_USAGE) from None
    token, created = api_token(settings.data_dir)
    # What a browser opens: a wildcard interface is no address to visit (nor a name the service answers to).
    shown = "127.0.0.1" if host in WILDCARD_ADDRESSES else f"[{host}]" if ":" in host else host
    base = f"http://{shown}:{port}"

    def climb_view(context):
        from frontend.viewer.app import ClimbView

        scene_view = ClimbView(
            context, host=host, port=view_port, panel_url=f"{base}/panel/", allowed_hosts=settings.allowed_hosts
        )
        note(f"3D view on http://{shown}:{scene_view.server.get_port()}/")
        return scene_view

    application = create_app(settings, view_factory=climb_view if view else None, warm_kernels=True)
    note(f"ParkourLab on {base}/  (API docs: {base}/docs)")
    note(f"data: {settings.data_dir}  database: {settings.database_url.split('://')[0]}")
    note(f"answers to Host names: {', '.join(settings.allowed_hosts)} (more: PARKOUR_ALLOWED_HOSTS=name,...)")
    if created:
        note(f"API token for changes (kept in {settings.data_dir / 'api_token'}): {token}")
    # As Jupyter does: a link that signs the browser in. The token rides in the fragment, which a
    # browser never sends to a server (so it is in no access log); the panel keeps it and takes it
    # out of the address bar.
    note(f"sign in to make changes: {base}/panel/#token={token}")
    # What start-up built lives as long as the service: out of the collector's way (gc.freeze), and
    # young collections about 30 times less often. Under 20 clients this took the service's CPU per request
    # from 11.5 to 11.0 ms and the reads' p95 from 276 to 239 ms (scripts/bench_load.py, side by side).
    gc.collect()
    gc.freeze()
    gc.set_threshold(YOUNG_COLLECTION_THRESHOLD, 50, 100)
    # A backstop for responses that do not end by themselves at a SIGTERM (the robot's event streams
    # do, backend/api/robot_events.py): uvicorn would otherwise wait for them for ever.
    uvicorn.run(application, host=host, port=port, log_level="info", timeout_graceful_shutdown=GRACEFUL_SHUTDOWN_S)
