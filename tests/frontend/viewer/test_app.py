"""The 3D view inside the service (frontend/viewer/app.py): a view per browser, what the API asks
of it (info, a replay for one panel's view, shared files) and what it answers when it cannot.

A real viser server on a free port; browsers are headless websocket clients (tests/frontend/
viewer/headless.py, the fixtures in conftest.py). The modes' own behaviour is tested beside them,
in tests/frontend/viewer/modes/.
"""

import time

from fastapi.testclient import TestClient

from backend.api.app import create_app
from backend.settings import Settings
from backend.store.models import Run
from frontend.viewer.modes.gait_search import GAIT_PRESETS
from tests.frontend.viewer.view_service import RUN, wait_for

FIRST_PRESET_ZETA0 = next(iter(GAIT_PRESETS.values()))[0][1]  # where every new browser's view starts


def test_the_view_reports_where_it_is_and_draws(service, browsers):
    client, _auth, view = service
    assert client.get("/api/v1/view").json()["clients"] == 0
    browser, session = browsers("panel-one")
    info = client.get("/api/v1/view", params={"viewer": "panel-one"}).json()
    assert info["available"] and info["port"] == view.server.get_port() and info["mode"] == "simulate"
    assert info["clients"] == 1 and session.viewer == "panel-one"
    frames, since = view.frames, time.monotonic()
    wait_for(lambda: view.frames > frames + 5)
    assert session.modes["simulate"].climb.current.clip.end > 0
    assert browser.updates_per_s(since) > 0, "the frames reach the browser"
    assert client.get("/api/v1/view", params={"viewer": "not a viewer"}).status_code == 422


def test_each_browser_has_its_own_view(browsers):
    _, mine = browsers("panel-mine")
    _, theirs = browsers("panel-theirs")
    simulate, other = mine.modes["simulate"], theirs.modes["simulate"]
    simulate.gui_zeta0_left.value = 0.88  # as if a person moved it (the callback runs)
    simulate.playback("Pause")
    mine.set_mode("replay")
    assert mine.mode.name == "replay" and theirs.mode.name == "simulate"
    assert other.gui_zeta0_left.value == FIRST_PRESET_ZETA0 and other.climb.controls.left.zeta0 == FIRST_PRESET_ZETA0
    assert other.playing
    time_before = other.time
    wait_for(lambda: other.time > time_before + 0.1)
    assert mine.scene.scene is not theirs.scene.scene, "each draws in its own browser's scene"
    assert FIRST_PRESET_ZETA0 != 0.88


def test_a_browser_that_leaves_is_dropped_and_the_next_starts_fresh(service, browsers):
    _client, _auth, view = service
    browser, session = browsers()
    simulate = session.modes["simulate"]
    simulate.gui_zeta0_left.value = 0.95
    browser.close()
    wait_for(lambda: not view.sessions)
    assert session.closed and simulate._gait_worker._shutdown, "its gait search is stopped"
    drawn = simulate.time
    time.sleep(0.2)
    assert simulate.time == drawn, "nothing is drawn for a browser that has gone"
    _, fresh = browsers()
    assert fresh.modes["simulate"].gui_zeta0_left.value == FIRST_PRESET_ZETA0
    assert fresh.mode.name == "simulate" and fresh.run_id is None


def test_a_replay_asked_for_a_view_still_loading_opens_when_it_connects(service, browsers):
    client, auth, _view = service
    run = client.post("/api/v1/runs", json=RUN, headers=auth).json()
    body = {"viewer": "panel-loading", "run_id": run["id"]}
    assert client.post("/api/v1/view/replay", json=body, headers=auth).json()["mode"] == "replay"
    _, session = browsers("panel-loading")
    wait_for(lambda: session.mode.name == "replay")
    assert session.run_id == run["id"]


def test_a_shared_file_is_kept_for_its_run_and_not_given_for_another_under_the_same_id(service):
    client, auth, view = service
    first = client.post("/api/v1/runs", json=RUN, headers=auth).json()
    shared = client.get(f"/api/v1/runs/{first['id']}/share.html").text
    assert client.get(f"/api/v1/runs/{first['id']}/share.html").text == shared and len(view._shared) == 1
    assert client.delete(f"/api/v1/runs/{first['id']}", headers=auth).status_code == 204
    other = RUN | {"controls": [{"psi0_deg": 32, "zeta0": 0.9}]}
    second = client.post("/api/v1/runs", json=other, headers=auth).json()
    assert second["id"] == first["id"], "SQLite gives the deleted run's id to the next"
    again = client.get(f"/api/v1/runs/{second['id']}/share.html").text
    assert again != shared and len(view._shared) == 2, "made again: another run's motion"


def test_replay_errors_name_the_problem(service, tmp_path):
    client, auth, view = service
    ask = {"viewer": "panel-one"}
    assert client.post("/api/v1/view/replay", json=ask | {"run_id": 999}, headers=auth).status_code == 404
    assert client.post("/api/v1/view/replay", json=ask | {"run_id": 0}, headers=auth).status_code == 422
    for viewer in (None, "short", "../../etc", "x" * 65):
        answer = client.post("/api/v1/view/replay", json={"viewer": viewer, "run_id": 1}, headers=auth)
        assert answer.status_code == 422 and answer.json()["detail"][0]["loc"] == ["body", "viewer"], viewer
    with view.context.sessions() as session:
        run = Run(kind="robot", status="failed", code_version="test", model={}, controls=[[30, 0.9], [30, 0.9]],
                  start_state=[0, 0], jumps=1, alpha=1, psi0_deg=30, zeta0=0.9, jumps_completed=0, climb=0,
                  results={})  # fmt: skip
        session.add(run)
        session.commit()
        robot_run = run.id
    answer = client.post("/api/v1/view/replay", json=ask | {"run_id": robot_run}, headers=auth)
    assert answer.status_code == 409 and "no tracker frames" in answer.json()["detail"]
    assert client.get(f"/api/v1/runs/{robot_run}/share.html").status_code == 409


def test_the_service_without_a_view_says_so(tmp_path):
    settings = Settings.from_environment(tmp_path / "data")
    with TestClient(create_app(settings)) as client:
        assert client.get("/api/v1/view").json()["available"] is False
        token = (settings.data_dir / "api_token").read_text().strip()
        body, auth = {"viewer": "panel-one", "run_id": 1}, {"Authorization": f"Bearer {token}"}
        answer = client.post("/api/v1/view/replay", json=body, headers=auth)
        assert answer.status_code == 503 and "3D view" in answer.json()["detail"]
