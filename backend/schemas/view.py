"""The 3D view: what it shows, and a stored run to replay in it."""

from __future__ import annotations

from typing import Annotated

from pydantic import BaseModel, Field

from backend.schemas.common import RecordRef, Strict

# A control panel's name for the 3D view it embeds: random, made by the panel for itself, and
# carried in the view's websocket path (frontend/viewer/handshake.py).
VIEWER_ID_PATTERN = r"^[A-Za-z0-9_-]{8,64}$"
ViewerId = Annotated[
    str,
    Field(pattern=VIEWER_ID_PATTERN, description="the panel's 3D view: 8-64 letters, digits, '-' or '_'"),
]


class ViewReplay(Strict):
    """Show a stored run in one panel's 3D view, optionally with a second run as a ghost beside it."""

    viewer: ViewerId
    run_id: RecordRef
    overlay_run_id: RecordRef | None = None


class ViewOut(BaseModel):
    """Where the 3D view is; ``mode`` and ``run_id`` are those of the view asked about (None when
    no viewer was named or its browser is not connected); ``clients``: browsers connected;
    ``updates_per_s``: frames drawn per second for each of them."""

    available: bool
    port: int | None = None
    mode: str | None = None
    run_id: int | None = None
    updates_per_s: float | None = None
    clients: int | None = None
    reason: str | None = None
    starting: bool = False  # not available yet: it is being built in the background
