"""Replay mode (frontend/viewer/modes/replay.py) in a browser's view of the service's 3D view: a
stored run with a ghost on a timeline, its height plot, and what it says of a run id it cannot
use. The frame it draws is held equal to the shared file's in tests/frontend/viewer/test_share.py.
A stored robot run in a world marks its touchdowns on the world's sides (last test).
"""

import math
import threading

import numpy as np

from backend.robot.touchdown import detect_touchdowns
from backend.schemas.worlds import WorldCreate
from backend.services import worlds
from backend.services.robot_plans import sides_at
from frontend.viewer.modes.replay import ReplayMode
from frontend.viewer.scene import ChuteScene
from frontend.viewer.viser_adapter import slider_marks
from sim_core.model.walls import Wall
from sim_core.world.files import world_from_document
from sim_core.world.trajectory import simulate_world_trajectory
from tests.frontend.viewer.test_share import SceneTree, decode_recording
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


def test_a_robot_run_in_a_world_marks_each_touchdown_where_its_foot_met_the_side(server, sessions):
    """A stored robot run in the narrowing world, its touchdowns detected from the frames of
    sim_core's climb there: replayed to its end, each marker is on the world's side at its foot's
    height (as live mode marks a live run's, tests/frontend/viewer/modes/test_live_world.py) —
    where the climb's feet were, not on the parallel walls. Drawn on a private viser server's
    scene, what the browser gets decoded as it decodes it."""
    from tests.backend.services.test_run_prediction import GAIT, JUMPS, ROBOT, START, store_run

    with sessions() as session:
        world = worlds.create(session, WorldCreate(name="narrowing chute", named="narrowing"))
        chute = world_from_document(world.world, ROBOT.leg_length)
        path, climb = simulate_world_trajectory(ROBOT.to_model(), chute, GAIT, START, JUMPS,
                                                sample_rate=100.0 * ROBOT.scales.time)  # fmt: skip
        path = path.to_si(ROBOT)
        frames = {"time": path.time, "x": path.x, "y": path.y}
        touchdowns = detect_touchdowns(*frames.values(), ROBOT, lambda k: GAIT[k + 1], side_at=sides_at(chute, ROBOT))
        run = store_run(session, touchdowns, world.id, {**frames, "pitch": np.full(path.time.size, math.nan)}).id
    assert len(touchdowns) == JUMPS - 1
    replay = ReplayMode(server, ChuteScene(server.scene, ROBOT), threading.RLock(), sessions)
    serializer = server.get_scene_serializer()
    replay.load(run)
    replay.time = replay.end
    replay.frame(1 / 60)
    serializer.insert_sleep(1 / 60)
    messages = decode_recording(serializer.serialize())["messages"]
    tree = SceneTree()
    for _time, message in messages:
        tree.apply(message)
    drawn = tree.shown()
    markers = sorted(node["position"] for name, node in drawn.items() if name.startswith("/chute/touchdowns/"))

    l0 = ROBOT.leg_length
    on_sides = [(chute.side("left" if td.wall == Wall.LEFT else "right").x_at(td.foot_height / l0) * l0, 0.0,
                 td.foot_height) for td in touchdowns]  # fmt: skip
    np.testing.assert_allclose(markers, sorted(on_sides), atol=1e-6, err_msg="each foot on its side at its height")
    # The climb's own feet (touchdown k + 1 of the climb is detected touchdown k), to the detector's error.
    legs = np.array([[GAIT[k].psi0, GAIT[k].zeta0] for k in range(1, JUMPS)])
    mirror = np.where(climb.sides[1:JUMPS] == 0, 1.0, -1.0)
    feet_x = (climb.states[1:JUMPS, 0] - mirror * legs[:, 1] * np.cos(legs[:, 0])) * l0
    np.testing.assert_allclose(
        [x for x, _y, _z in on_sides], feet_x, atol=2e-3 * l0, err_msg="where the climb's feet were"
    )
    half = 0.5 * ROBOT.wall_distance
    assert np.abs(np.abs(feet_x) - half).max() > 0.01, "the parallel walls' x is not the world's"
