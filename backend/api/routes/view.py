"""The 3D view: where it is, a stored run on its timeline, and a run's replay as one HTML file."""

from __future__ import annotations

from typing import Annotated

from fastapi import APIRouter, HTTPException, Query, Request
from fastapi.responses import HTMLResponse

from backend import schemas
from backend.api.deps import AUTHORIZED, OptionalRecordId, RecordId, SceneView, view_of, view_unavailable_reason

router = APIRouter(tags=["view"])


@router.get("/api/v1/view", response_model=schemas.ViewOut)
def view_info(
    request: Request, viewer: Annotated[str | None, Query(pattern=schemas.VIEWER_ID_PATTERN)] = None
) -> schemas.ViewOut:
    """Where the 3D view is (its own port on this host), and what the panel ``viewer``'s view shows."""
    try:
        return schemas.ViewOut.model_validate(view_of(request).info(viewer))
    except HTTPException:
        starter = request.app.state.view_starter
        starting = starter is not None and starter.starting
        return schemas.ViewOut(available=False, reason=view_unavailable_reason(request), starting=starting)


@router.post("/api/v1/view/replay", dependencies=AUTHORIZED, response_model=schemas.ViewOut)
def view_replay(body: schemas.ViewReplay, view: SceneView) -> schemas.ViewOut:
    """Show a stored run in the 3D view of the panel ``viewer`` (replay mode), optionally with
    another as a ghost. Nobody else's view changes; a view still loading gets it when it connects."""
    return schemas.ViewOut.model_validate(view.open_run(body.viewer, body.run_id, body.overlay_run_id))


@router.get("/api/v1/runs/{run_id}/share.html", response_class=HTMLResponse)
def share_run(run_id: RecordId, view: SceneView, overlay_run_id: OptionalRecordId = None) -> HTMLResponse:
    """The run's 3D replay as one standalone HTML file: it plays offline, from disk, in any browser."""
    html = view.share_html(run_id, overlay_run_id)
    disposition = f'attachment; filename="parkourlab-run-{run_id}.html"'
    return HTMLResponse(html, headers={"Content-Disposition": disposition})
