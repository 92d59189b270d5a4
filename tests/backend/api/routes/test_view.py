"""The 3D view's routes (backend/api/routes/view.py) over a stand-in view: what each asks of the view,
the token for a change, the viewer's id checked, and why there is no view when there is none."""

import pytest
from fastapi.testclient import TestClient

from backend.api.app import create_app
from backend.api.deps import VIEW_NOT_STARTED

VIEWER = "panel-one"


class RecordingView:
    """A SceneView that answers as the viser one does and keeps what it was asked."""

    def __init__(self, _context):
        self.asked = []

    def info(self, viewer=None) -> dict:
        self.asked.append(("info", viewer))
        return {"available": True, "port": 8001, "mode": "idle", "clients": 1}

    def open_run(self, viewer, run_id, overlay_run_id=None) -> dict:
        self.asked.append(("open_run", viewer, run_id, overlay_run_id))
        return self.info(viewer) | {"mode": "replay", "run_id": run_id}

    def share_html(self, run_id, overlay_run_id=None) -> str:
        self.asked.append(("share_html", run_id, overlay_run_id))
        return f"<!doctype html><p>run {run_id}</p>"

    def close(self) -> None:
        pass


@pytest.fixture
def database_url():
    return None  # SQLite: the stand-in view reads nothing from the store


@pytest.fixture
def viewed(settings, compute):
    """``(client, view, token header)``: the service with its stand-in view built and running."""
    app = create_app(settings, compute=compute, run_jobs=False, view_factory=RecordingView)
    with TestClient(app) as client:
        yield client, app.state.view_starter.wait(10), {"Authorization": f"Bearer {app.state.token}"}


def test_the_view_says_where_it_is_and_what_a_viewer_sees(viewed):
    client, view, _auth = viewed
    info = client.get("/api/v1/view", params={"viewer": VIEWER}).json()
    assert (info["available"], info["port"], info["mode"], info["clients"]) == (True, 8001, "idle", 1)
    assert view.asked == [("info", VIEWER)]
    assert client.get("/api/v1/view", params={"viewer": "a b"}).status_code == 422, "not a viewer id"


def test_a_replay_needs_the_token_and_opens_the_run_in_that_viewer_only(viewed):
    client, view, auth = viewed
    body = {"viewer": VIEWER, "run_id": 7, "overlay_run_id": 3}
    assert client.post("/api/v1/view/replay", json=body).status_code == 401
    assert view.asked == [], "refused before the view was asked"
    shown = client.post("/api/v1/view/replay", json=body, headers=auth).json()
    assert (shown["mode"], shown["run_id"]) == ("replay", 7)
    assert view.asked[0] == ("open_run", VIEWER, 7, 3)
    assert client.post("/api/v1/view/replay", json=body | {"run_id": 0}, headers=auth).status_code == 422


def test_a_shared_replay_is_one_html_file_to_download(viewed):
    client, view, _auth = viewed
    page = client.get("/api/v1/runs/12/share.html", params={"overlay_run_id": 4})
    assert page.status_code == 200 and page.headers["content-type"].startswith("text/html")
    assert page.headers["content-disposition"] == 'attachment; filename="parkourlab-run-12.html"'
    assert page.text == "<!doctype html><p>run 12</p>" and view.asked == [("share_html", 12, 4)]


def test_without_a_view_a_replay_or_a_shared_file_is_a_503_saying_why(client, auth):
    """GET /api/v1/view says it too, as ``reason``: tests/backend/services/test_view.py."""
    replay = client.post("/api/v1/view/replay", json={"viewer": VIEWER, "run_id": 1}, headers=auth)
    assert replay.status_code == 503 and replay.json()["detail"] == VIEW_NOT_STARTED
    shared = client.get("/api/v1/runs/1/share.html")
    assert shared.status_code == 503 and shared.json()["detail"] == VIEW_NOT_STARTED
