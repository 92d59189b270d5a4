"""The view interface: what the service lends a view, the view's lifetime, and who implements it.

The viser view itself is tested in tests/frontend/viewer/test_view.py; here a stand-in view is enough.
"""

import inspect

import pytest
from fastapi.testclient import TestClient

from backend.api.app import create_app
from backend.services.records import list_experiments
from backend.services.robot import RobotService
from backend.services.view import SceneView, ViewContext
from backend.settings import Settings
from frontend.viewer.app import ClimbView

SCENE_VIEW_METHODS = ("info", "open_run", "share_html", "close")


class StandInView:
    """A SceneView that keeps what it was given and whether it was closed."""

    def __init__(self, context: ViewContext):
        self.context = context
        self.closed = False

    def info(self) -> dict:
        return {"available": True, "port": None, "mode": "idle"}

    def open_run(self, run_id: int, overlay_run_id: int | None = None) -> dict:
        return self.info() | {"run_id": run_id}

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
        (view,) = built
        assert app.state.view is view and not view.closed
        with view.context.sessions() as session:
            assert list_experiments(session, limit=5, cursor=None) == ([], None), "a migrated database"
        assert isinstance(view.context.robot_service, RobotService)
        assert view.context.robot_service.status()["state"] == "disconnected"
    assert view.closed, "the service closes its view at shutdown"


def test_without_a_factory_there_is_no_view(settings):
    app = create_app(settings, run_jobs=False)
    with TestClient(app):
        assert app.state.view is None


@pytest.mark.parametrize("implementation", [ClimbView, StandInView])
@pytest.mark.parametrize("method", SCENE_VIEW_METHODS)
def test_views_implement_scene_view(implementation, method):
    """The viser view (and the stand-in above) take the protocol's arguments with its defaults."""
    expected = inspect.signature(getattr(SceneView, method)).parameters
    got = inspect.signature(getattr(implementation, method)).parameters
    assert list(got) == list(expected), f"{implementation.__name__}.{method} arguments"
    assert [p.default for p in got.values()] == [p.default for p in expected.values()]
