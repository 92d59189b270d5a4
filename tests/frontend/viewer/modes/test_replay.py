"""Replay mode (frontend/viewer/modes/replay.py) in a browser's view of the service's 3D view: a
stored run with a ghost on a timeline, its height plot, and what it says of a run id it cannot
use. The frame it draws is held equal to the shared file's in tests/frontend/viewer/test_share.py.
"""

import numpy as np

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
    assert "Run id must be at least 1" in replay.readout(60.0)
