"""The 3D view: what it shows, and a stored run to replay in it."""

from __future__ import annotations

from pydantic import BaseModel

from backend.schemas.common import RecordRef, Strict


class ViewReplay(Strict):
    """Show a stored run in the 3D view, optionally with a second run as a ghost beside it."""

    run_id: RecordRef
    overlay_run_id: RecordRef | None = None


class ViewOut(BaseModel):
    available: bool
    port: int | None = None
    mode: str | None = None
    run_id: int | None = None
    updates_per_s: float | None = None
    clients: int | None = None
    reason: str | None = None
    starting: bool = False  # not available yet: it is being built in the background
