"""Replay mode (frontend/viewer/modes/replay.py) in a browser's view of the service's 3D view: a
stored run with a ghost on a timeline, its height plot, and what it says of a run id it cannot
use. The frame it draws is held equal to the shared file's in tests/frontend/viewer/test_share.py.
"""

import numpy as np

from frontend.viewer.viser_adapter import slider_marks
from tests.frontend.viewer.view_service import RUN, wait_for


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
    wait_for(lambda: replay.time > 0.2)
    html = client.get(f"/api/v1/runs/{stored['id']}/share.html")
    assert html.status_code == 200 and "attachment" in html.headers["content-disposition"]
    assert "window.__VISER_EMBED_DATA__" in html.text


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
    wait_for(lambda: dot() > 0.3)
    assert abs(dot() - replay.time) < 0.3, "the dot is where the body is on the timeline"


def test_a_half_typed_run_id_is_named_in_the_readout(browsers):
    _, session = browsers()
    replay = session.modes["replay"]
    replay.gui_run.value = 0
    replay._on_load(None)
    assert "Run id must be a whole number from 1 to 2147483647, got 0" in replay.readout(60.0)


def test_a_run_id_out_of_range_is_refused_not_held_to_1(service, browsers):
    """Run id -1 loaded run 1: the box had min 1, and the browser holds a number box to its ends
    when it loses focus. Now it has no ends there: -1 comes as typed, Load refuses it in the
    readout, naming the field and its range, and the run on the timeline stays."""
    client, auth, _view = service
    browser, session = browsers()
    replay = session.modes["replay"]
    assert (replay.gui_run.min, replay.gui_overlay.min) == (None, None), "the browser changes nothing typed"
    run = client.post("/api/v1/runs", json=RUN, headers=auth).json()
    replay.load(run["id"])
    browser.set_gui("Run id", -1)
    wait_for(lambda: replay.gui_run.value == -1)
    replay._on_load(None)  # Load
    readout = replay.readout(60.0)
    assert "**Cannot replay:** Run id must be a whole number from 1 to 2147483647, got -1" in readout, readout
    assert replay.recording.run_id == run["id"] and f"still showing run {run['id']}" in readout
    browser.set_gui("Overlay run id (0: none)", -3)
    browser.set_gui("Run id", run["id"])
    wait_for(lambda: replay.gui_overlay.value == -3 and replay.gui_run.value == run["id"])
    replay._on_load(None)
    assert "Overlay run id (0: none) must be a whole number from 0 to 2147483647, got -3" in replay.readout(60.0)


def test_a_time_or_speed_typed_past_its_slider_is_refused(service, browsers):
    """The timeline and the speed are sliders: a value typed past an end reaches the service as the
    browser holds it (one step past the range), and is not used: the replay stays at its time and
    speed, and the readout names the slider, its range and what was typed."""
    client, auth, _view = service
    browser, session = browsers()
    replay = session.modes["replay"]
    replay.load(client.post("/api/v1/runs", json=RUN, headers=auth).json()["id"])
    end = replay.end
    assert (replay.gui_time.min, replay.gui_time.max) == (-0.01, round(end + 0.01, 2))
    assert slider_marks(replay.gui_time) == ((0.0, "0"), (end, f"{end:g}")), "the marks move with the run"
    browser.set_gui("Time [s]", 999.0)  # as typed
    wait_for(lambda: "got 999" in (replay.input_note or ""))
    browser.set_gui("Time [s]", replay.gui_time.max)  # as the browser holds it when the box loses focus
    wait_for(lambda: replay.gui_time.value == replay.gui_time.max)
    assert replay.time == 0.0, "the replay did not move to the end"
    assert f"Time [s] must be 0 to {end:g}, got 999" in replay.readout(60.0)
    browser.set_gui("Time [s]", 1.0)
    wait_for(lambda: replay.time == 1.0)
    browser.set_gui("speed [×]", 10.0)
    wait_for(lambda: "got 10" in (replay.input_note or ""))
    browser.set_gui("speed [×]", 4.1)
    wait_for(lambda: replay.gui_speed.value == 4.1)
    assert replay.speed == 1.0 and "speed [×] must be 0.1 to 4, got 10" in replay.readout(60.0)
    replay.playback("Play")
    with session.lock:
        replay.frame(0.5)
    assert replay.time == 1.5, "played at the speed in use"
