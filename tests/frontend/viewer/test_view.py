"""The 3D view inside the service: a view per browser, its API, replay of stored runs, sharing,
and the GUI's wiring.

A real viser server on a free port; browsers are headless websocket clients (tests/frontend/
viewer/headless.py), and each one's GUI is driven from Python as its callbacks would drive it.
"""

import dataclasses
import time

import numpy as np
import pytest
from fastapi.testclient import TestClient

from backend.api.app import create_app
from backend.settings import Settings
from backend.store.models import Run
from frontend.viewer.app import ClimbView
from frontend.viewer.modes import GAIT_PRESETS
from frontend.viewer.recordings import load_recording
from sim_core import get_preset
from sim_core.climb import ClimbEnd
from tests.frontend.viewer.headless import HeadlessViewer

ROBOT = get_preset("paper")
FIRST_PRESET_ZETA0 = next(iter(GAIT_PRESETS.values()))[0][1]  # where every new browser's view starts
RUN = {
    "controls": [{"psi0_deg": 30, "zeta0": 0.87}, {"psi0_deg": 30, "zeta0": 0.9}],
    "start": {"xdot": -0.8, "ydot": -0.15},
    "jumps": 6,
}


@pytest.fixture
def service(tmp_path):
    settings = Settings.from_environment(tmp_path / "data")
    app = create_app(settings, view_factory=lambda context: ClimbView(context, port=0))
    with TestClient(app) as client:
        token = (settings.data_dir / "api_token").read_text().strip()
        view = app.state.view_starter.wait(60)  # built in the background, after start-up
        assert view is not None, app.state.view_starter.unavailable_reason
        yield client, {"Authorization": f"Bearer {token}"}, view


@pytest.fixture
def browsers(service):
    """``open(viewer)``: a headless browser's view of the service's 3D view, and its session."""
    _client, _auth, view = service
    opened = []

    def open_view(viewer: str | None = None):
        before = set(view.sessions)
        opened.append(HeadlessViewer(view.server.get_port(), viewer))
        _wait_for(lambda: set(view.sessions) - before)
        (client_id,) = set(view.sessions) - before
        return opened[-1], view.sessions[client_id]

    yield open_view
    for browser in opened:
        browser.close()


def _wait_for(condition, timeout=10.0):
    deadline = time.monotonic() + timeout
    while not condition():
        assert time.monotonic() < deadline, "timed out"
        time.sleep(0.02)


def test_the_view_reports_where_it_is_and_draws(service, browsers):
    client, _auth, view = service
    assert client.get("/api/v1/view").json()["clients"] == 0
    browser, session = browsers("panel-one")
    info = client.get("/api/v1/view", params={"viewer": "panel-one"}).json()
    assert info["available"] and info["port"] == view.server.get_port() and info["mode"] == "simulate"
    assert info["clients"] == 1 and session.viewer == "panel-one"
    frames, since = view.frames, time.monotonic()
    _wait_for(lambda: view.frames > frames + 5)
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
    _wait_for(lambda: other.time > time_before + 0.1)
    assert mine.scene.scene is not theirs.scene.scene, "each draws in its own browser's scene"
    assert FIRST_PRESET_ZETA0 != 0.88


def test_a_browser_that_leaves_is_dropped_and_the_next_starts_fresh(service, browsers):
    _client, _auth, view = service
    browser, session = browsers()
    simulate = session.modes["simulate"]
    simulate.gui_zeta0_left.value = 0.95
    browser.close()
    _wait_for(lambda: not view.sessions)
    assert session.closed and simulate._gait_worker._shutdown, "its gait search is stopped"
    drawn = simulate.time
    time.sleep(0.2)
    assert simulate.time == drawn, "nothing is drawn for a browser that has gone"
    _, fresh = browsers()
    assert fresh.modes["simulate"].gui_zeta0_left.value == FIRST_PRESET_ZETA0
    assert fresh.mode.name == "simulate" and fresh.run_id is None


def test_a_stored_run_replays_with_a_ghost_in_the_panel_that_asked_and_shares_as_html(service, browsers):
    client, auth, _view = service
    _, asking = browsers("panel-asking")
    _, watching = browsers("panel-other")
    stored = client.post("/api/v1/runs", json=RUN | {"trajectory_rate": 100}, headers=auth).json()
    regenerated = client.post("/api/v1/runs", json=RUN, headers=auth).json()
    body = {"viewer": "panel-asking", "run_id": stored["id"], "overlay_run_id": regenerated["id"]}
    assert client.post("/api/v1/view/replay", json=body).status_code == 401
    info = client.post("/api/v1/view/replay", json=body, headers=auth).json()
    assert info["mode"] == "replay" and info["run_id"] == stored["id"]
    assert watching.mode.name == "simulate" and watching.run_id is None, "nobody else's view changes"
    replay = asking.modes["replay"]
    assert replay.overlay.run_id == regenerated["id"]
    # A run stored without its path is simulated again: the same motion at the same instants.
    recording, again = replay.recording, replay.overlay
    times = np.linspace(0.0, min(recording.duration, again.duration), 50)
    assert np.allclose(
        [recording.clip.pose_at(t).y for t in times], [again.clip.pose_at(t).y for t in times], atol=2e-3
    )
    replay.playback("Play")
    _wait_for(lambda: replay.time > 0.2)
    html = client.get(f"/api/v1/runs/{stored['id']}/share.html")
    assert html.status_code == 200 and "attachment" in html.headers["content-disposition"]
    assert "window.__VISER_EMBED_DATA__" in html.text


def test_a_replay_asked_for_a_view_still_loading_opens_when_it_connects(service, browsers):
    client, auth, _view = service
    run = client.post("/api/v1/runs", json=RUN, headers=auth).json()
    body = {"viewer": "panel-loading", "run_id": run["id"]}
    assert client.post("/api/v1/view/replay", json=body, headers=auth).json()["mode"] == "replay"
    _, session = browsers("panel-loading")
    _wait_for(lambda: session.mode.name == "replay")
    assert session.run_id == run["id"]


def test_the_replay_plot_is_in_seconds_with_a_dot_moving_with_the_body(service, browsers):
    client, auth, _view = service
    _, session = browsers("panel-plot")
    run = client.post("/api/v1/runs", json=RUN | {"trajectory_rate": 100}, headers=auth).json()
    client.post("/api/v1/view/replay", json={"viewer": "panel-plot", "run_id": run["id"]}, headers=auth)
    replay = session.modes["replay"]
    assert replay.plot.scales["x"] == {"time": False}, "seconds of the run, not dates from 1970"
    low, high = replay.plot.scales["y"]["range"]  # fixed: uPlot ranging over NaN blanks the plot
    heights = replay.plot.data[1]
    assert low < np.nanmin(heights) < np.nanmax(heights) < high

    def dot():
        grid, now = replay.plot.data[0], replay.plot.data[-1]
        (k,) = np.flatnonzero(np.isfinite(now))
        return grid[k]

    assert dot() == 0.0
    replay.playback("Play")
    _wait_for(lambda: dot() > 0.3)
    assert abs(dot() - replay.time) < 0.3, "the dot is where the body is on the timeline"


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


def test_presets_and_sliders_do_not_feed_back(browsers):
    _, session = browsers()
    simulate = session.modes["simulate"]
    name = list(GAIT_PRESETS)[2]
    simulate.set_preset(name)
    assert simulate.gui_preset.value == name, "setting the sliders from a preset does not mark it custom"
    assert not simulate.gui_symmetric.value and simulate.gui_zeta0_right.value == pytest.approx(0.9505)
    controls = simulate.controls()
    assert (controls.left.zeta0, controls.right.zeta0, controls.right.psi0_deg) == (0.90, 0.9505, pytest.approx(35))
    _wait_for(lambda: simulate.gait is not None and simulate.gait_note != "searching…")
    assert simulate.gait.period == 4 and simulate.gait.stable, simulate.gait_note
    simulate.gui_zeta0_left.value = 0.88  # as if a person moved it (the callback runs)
    assert simulate.gui_preset.value == "custom"
    simulate.gui_symmetric.value = True
    assert simulate.gui_zeta0_right.value == 0.88 and simulate.gui_zeta0_right.disabled
    assert simulate.climb.controls.right.zeta0 == 0.88


def test_half_typed_values_never_reach_the_simulator(browsers):
    _, session = browsers()
    simulate = session.modes["simulate"]
    _wait_for(lambda: simulate.gait_note != "searching…")
    in_use = simulate.climb.controls
    for handle, typed in ((simulate.gui_psi0_left, 0.0), (simulate.gui_zeta0_left, 0.9999), (simulate.gui_gravity, 0)):
        whole = handle.value
        handle.value = typed  # what a number box sends on the way to a whole value
        assert simulate.climb.controls == in_use, handle.label
        assert handle.label in simulate.input_note and "must be" in simulate.input_note
        assert "**Not in use yet:**" in simulate.readout(60.0)
        handle.value = whole  # typed to the end
        assert simulate.input_note is None and simulate.climb.controls == in_use
    simulate.gui_speed.value, before = -3.0, simulate.time
    simulate.frame(0.1)
    assert simulate.time > before, "a half-typed speed plays at the slowest, never backwards"
    replay = session.modes["replay"]
    replay.gui_run.value = 0
    replay._on_load(None)
    assert "Run id must be at least 1" in replay.readout(60.0)


def test_simulate_mode_stops_a_descending_climb_at_the_floor_and_says_so(browsers):
    _, session = browsers()
    simulate = session.modes["simulate"]
    _wait_for(lambda: simulate.gait_note != "searching…")  # the first search, which restarts the climb
    simulate.gui_psi0_left.value = 30.0
    simulate.gui_zeta0_left.value = 0.99  # beyond jumping in place: the gait descends
    _wait_for(lambda: simulate.gait_note != "searching…")
    with session.lock:
        simulate.restart()
        simulate.playback("Pause")
        simulate.time = 300.0
        simulate.frame(0.0)
        readout = simulate.readout(60.0)
    assert simulate.climb.current.failure is ClimbEnd.FLOOR
    assert "**Failure:** **floor** at jump" in readout and "the body reached the chute's floor" in readout, readout
    assert "height** 0.000 m" in readout, readout


def test_the_service_without_a_view_says_so(tmp_path):
    settings = Settings.from_environment(tmp_path / "data")
    with TestClient(create_app(settings)) as client:
        assert client.get("/api/v1/view").json()["available"] is False
        token = (settings.data_dir / "api_token").read_text().strip()
        body, auth = {"viewer": "panel-one", "run_id": 1}, {"Authorization": f"Bearer {token}"}
        answer = client.post("/api/v1/view/replay", json=body, headers=auth)
        assert answer.status_code == 503 and "3D view" in answer.json()["detail"]


def test_recordings_put_sim_runs_between_the_walls(service):
    client, auth, view = service
    run = client.post("/api/v1/runs", json=RUN | {"trajectory_rate": 200}, headers=auth).json()
    recording = load_recording(view.context.sessions, run["id"])
    half = 0.5 * ROBOT.wall_distance
    assert set(np.unique(recording.touchdowns[:, 1])) == {-1, 1}
    stance_feet = recording.clip.foot_x[recording.clip.phase == 0]
    assert np.allclose(np.abs(stance_feet), half), "stance feet are on the walls"
    assert np.all(np.abs(recording.clip.x) < half)


def test_live_mode_shows_the_robot_to_everyone_who_chooses_it_with_the_model_beside_it(service, browsers, virtual):
    client, auth, _view = service
    robot, port = virtual
    (_, watching), (_, also), (_, simulating) = browsers(), browsers(), browsers()
    try:
        answer = client.post("/api/v1/robot/connect", json={"url": robot.url, "tracker_port": port}, headers=auth)
        assert answer.status_code == 200, answer.text
        watching.set_mode("live")
        also.set_mode("live")
        live = watching.modes["live"]
        controls = [{"psi0_deg": 30, "zeta0": 0.87}, {"psi0_deg": 30, "zeta0": 0.9}]
        assert (
            client.post("/api/v1/robot/runs", json={"controls": controls, "jumps": 6}, headers=auth).status_code == 202
        )
        _wait_for(lambda: not client.get("/api/v1/robot").json()["run"]["active"], timeout=30)
        # A loaded machine's control loop may see a touchdown or more past the sixth before it ends the
        # run: the views show what the run recorded, however many that was.
        recorded = client.get("/api/v1/robot").json()["run"]["touchdowns"]
        assert recorded >= 6
        _wait_for(lambda: live._marked == recorded and also.modes["live"]._marked == recorded)
        assert watching.scene.ghost.visible, "the model's jump from the last touchdown is drawn"
        ghost_trail = watching.scene.live_ghost_trail
        assert ghost_trail.finished.count or len(ghost_trail.piece) >= 2, "and its trail since the touchdown"
        assert simulating.mode.name == "simulate" and simulating.modes["live"]._marked == 0, "choosing is each one's"
        # Without noise the robot is the model: the ghost lands where the robot touched down.
        assert abs(live.last_error) < 0.01, f"model's touchdown height error {live.last_error:+.4f} m"
        assert f"Touchdowns this run:** {recorded} " in live.readout(60.0)
    finally:
        client.post("/api/v1/robot/disconnect", headers=auth)


def test_the_live_ghost_can_predict_with_a_calibrated_model(service, browsers):
    """A robot unlike the paper's: the ghost of a calibration of it lands where the robot touches
    down, the paper's does not; each browser chooses its own."""
    import socket

    from backend.robot.virtual import VirtualRobot
    from backend.store.models import ModelPreset
    from sim_core.noise import NO_NOISE
    from tests.helpers import free_port
    from tests.tracked_climbs import Truth

    client, auth, _view = service
    truth = Truth.of(alpha=72.0, c_zeta=1.25, c_psi=0.8, psi0_offset_deg=(0.6, -0.8), zeta0_offset=(0.004, -0.005))
    with client.app.state.sessions() as session:
        session.add(ModelPreset(name="truth", base="paper", physical=dataclasses.asdict(truth.robot),
                                offsets=truth.offsets.to_dict(), fit={}, runs=[], code_version="test"))  # fmt: skip
        session.commit()
    port = free_port(socket.SOCK_DGRAM)
    robot = VirtualRobot(tracker_to=("127.0.0.1", port), robot=truth.robot, leg_offsets=truth.offsets,
                         noise=NO_NOISE, tracker_noise=0.0, drop_rate=0.0, speed=4.0).start()  # fmt: skip
    (_, paper_view), (_, calibrated_view) = browsers(), browsers()
    try:
        answer = client.post("/api/v1/robot/connect", json={"url": robot.url, "tracker_port": port}, headers=auth)
        assert answer.status_code == 200, answer.text
        paper, calibrated = paper_view.modes["live"], calibrated_view.modes["live"]
        assert calibrated.gui_ghost_model.options == ("paper", "truth")
        calibrated.use_ghost_model("truth")
        paper_view.set_mode("live")
        calibrated_view.set_mode("live")
        controls = [{"psi0_deg": 30, "zeta0": 0.87}, {"psi0_deg": 30, "zeta0": 0.9}]
        assert (
            client.post("/api/v1/robot/runs", json={"controls": controls, "jumps": 6}, headers=auth).status_code == 202
        )
        _wait_for(lambda: not client.get("/api/v1/robot").json()["run"]["active"], timeout=30)
        _wait_for(lambda: paper._marked >= 6 and calibrated._marked >= 6)
        assert abs(calibrated.last_error) < 0.002, f"the calibrated ghost's error {calibrated.last_error:+.4f} m"
        assert abs(paper.last_error) > 3 * abs(calibrated.last_error), (paper.last_error, calibrated.last_error)
    finally:
        client.post("/api/v1/robot/disconnect", headers=auth)
        robot.stop()
