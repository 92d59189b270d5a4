"""The view interface: what the service lends a view, the view's lifetime, and who implements it.

The viser view itself is tested in tests/frontend/viewer/test_view.py; here a stand-in view is enough.
"""

import inspect
import threading

import pytest
from fastapi.testclient import TestClient

from backend.api.app import create_app
from backend.services.experiments import list_page
from backend.services.robot import RobotService
from backend.services.view import SceneView, ViewContext, ViewStarter
from backend.settings import Settings
from frontend.viewer.app import ClimbView

SCENE_VIEW_METHODS = ("info", "open_run", "share_html", "close")


class StandInView:
    """A SceneView that keeps what it was given and whether it was closed."""

    def __init__(self, context: ViewContext):
        self.context = context
        self.closed = False

    def info(self, viewer: str | None = None) -> dict:
        return {"available": True, "port": None, "mode": "idle"}

    def open_run(self, viewer: str, run_id: int, overlay_run_id: int | None = None) -> dict:
        return self.info(viewer) | {"run_id": run_id}

    def share_html(self, run_id: int, overlay_run_id: int | None = None) -> str:
        return f"<p>run {run_id}</p>"

    def close(self) -> None:
        self.closed = True


@pytest.fixture
def settings(tmp_path):
    return Settings.from_environment(tmp_path / "data")


def test_the_view_gets_the_services_sessions_and_robot_and_is_closed(settings):
    built = []

    def factory(context: ViewContext) -> SceneView:
        built.append(StandInView(context))
        return built[-1]

    app = create_app(settings, run_jobs=False, view_factory=factory)
    assert built == [], "the view is built at start-up, not with the app"
    with TestClient(app):
        view = app.state.view_starter.wait(10)
        assert built == [view] and not view.closed
        with view.context.sessions() as session:
            empty = {"items": [], "next_cursor": None, "total": 0}
            assert list_page(session, limit=5, cursor=None).model_dump() == empty, "a migrated database"
        assert isinstance(view.context.robot_service, RobotService)
        assert view.context.robot_service.status()["state"] == "disconnected"
    assert view.closed, "the service closes its view at shutdown"


def test_without_a_factory_there_is_no_view(settings):
    app = create_app(settings, run_jobs=False)
    with TestClient(app) as client:
        assert app.state.view_starter is None
        assert client.get("/api/v1/view").json() == {
            "available": False,
            "reason": "the 3D view is not running (it starts with `parkour serve`)",
            "starting": False,
            **dict.fromkeys(("port", "mode", "run_id", "updates_per_s", "clients")),
        }


def test_the_api_answers_while_the_view_is_starting(settings):
    release = threading.Event()

    def slow_factory(context: ViewContext) -> SceneView:
        release.wait(10)
        return StandInView(context)

    app = create_app(settings, run_jobs=False, view_factory=slow_factory)
    with TestClient(app) as client:
        assert client.get("/api/v1/health").status_code == 200
        info = client.get("/api/v1/view").json()
        assert info["available"] is False and info["starting"] is True and "starting" in info["reason"]
        replay = {"viewer": "panel-one", "run_id": 1}
        assert client.post("/api/v1/view/replay", json=replay, headers=_auth(settings)).status_code == 503
        release.set()
        view = app.state.view_starter.wait(10)
        assert client.get("/api/v1/view").json()["mode"] == "idle"
    assert view.closed


def test_a_view_that_fails_to_start_leaves_the_api_running_and_says_why(settings):
    def broken(_context: ViewContext) -> SceneView:
        raise OSError("port 8001 in use")

    app = create_app(settings, run_jobs=False, view_factory=broken)
    with TestClient(app) as client:
        assert app.state.view_starter.wait(10) is None
        info = client.get("/api/v1/view").json()
        assert info["available"] is False and not info["starting"]
        assert info["reason"] == "the 3D view did not start: port 8001 in use"
        assert client.get("/api/v1/health").status_code == 200


def test_a_view_still_starting_at_shutdown_is_closed_once_built():
    release = threading.Event()
    views = []

    def slow_factory(context: ViewContext) -> SceneView:
        release.wait(10)
        views.append(StandInView(context))
        return views[-1]

    starter = ViewStarter(slow_factory, ViewContext(sessions=lambda: None, robot_service=None)).start()
    assert starter.view is None and starter.starting
    threading.Timer(0.05, release.set).start()
    starter.close()  # waits for the start, then closes what it built
    assert views[0].closed and not starter.starting


def _auth(settings) -> dict:
    return {"Authorization": f"Bearer {(settings.data_dir / 'api_token').read_text().strip()}"}


@pytest.mark.parametrize("implementation", [ClimbView, StandInView])
@pytest.mark.parametrize("method", SCENE_VIEW_METHODS)
def test_views_implement_scene_view(implementation, method):
    """The viser view (and the stand-in above) take the protocol's arguments with its defaults."""
    expected = inspect.signature(getattr(SceneView, method)).parameters
    got = inspect.signature(getattr(implementation, method)).parameters
    assert list(got) == list(expected), f"{implementation.__name__}.{method} arguments"
    assert [p.default for p in got.values()] == [p.default for p in expected.values()]


def test_a_view_built_after_shutdown_gave_up_waiting_is_closed_too(monkeypatch):
    import backend.services.view as view_service

    monkeypatch.setattr(view_service, "CLOSE_WAIT_S", 0.01)
    release, views = threading.Event(), []

    def slow_factory(context: ViewContext) -> SceneView:
        release.wait(10)
        views.append(StandInView(context))
        return views[-1]

    starter = ViewStarter(slow_factory, ViewContext(sessions=lambda: None, robot_service=None)).start()
    starter.close()  # gives up waiting: the view is not built yet
    release.set()
    starter.wait(10)
    assert views[0].closed and starter.view is None


def test_a_run_in_a_world_is_read_with_its_world_and_worlds_are_listed(settings):
    """No longer refused: stored_path carries the run's world as the §8 JSON in l0; the worlds
    simulate mode offers are listed newest first and read back in l0."""
    from backend.services.view import stored_path, stored_world, stored_worlds

    built = []
    app = create_app(
        settings, run_jobs=False, view_factory=lambda context: built.append(StandInView(context)) or built[-1]
    )
    with TestClient(app) as client:
        auth = {"Authorization": f"Bearer {(settings.data_dir / 'api_token').read_text().strip()}"}
        view = app.state.view_starter.wait(10)
        first = client.post("/api/v1/worlds", json={"name": "steps", "named": "staircase"}, headers=auth).json()
        second = client.post("/api/v1/worlds", json={"name": "drawn", "random": {"seed": 3}}, headers=auth)
        assert second.status_code == 201, second.text
        second = second.json()
        body = {"controls": [{"psi0_deg": 30, "zeta0": 0.9}], "start": {"xdot": -1.0, "ydot": 0.5}, "jumps": 3,
                "world_id": first["id"]}  # fmt: skip
        run = client.post("/api/v1/runs", json=body, headers=auth).json()
        path = stored_path(view.context.sessions, run["id"])
        assert path.world_id == first["id"] and path.world["name"] == "steps" and path.world["units"] == "l0"
        assert stored_worlds(view.context.sessions) == [(second["id"], "drawn"), (first["id"], "steps")]
        assert stored_world(view.context.sessions, first["id"]) == path.world
