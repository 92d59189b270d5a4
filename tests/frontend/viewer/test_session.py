"""One browser's view (frontend/viewer/session.py) on a private viser server, the browser a
headless one (headless.py): it starts in simulate mode on its own scene; choosing a mode swaps the
modes' GUI and starts the scene afresh; a stored run goes on its timeline; each frame draws the
mode and, when asked, its readout; once closed it draws and computes nothing.

A view per browser inside the service is tested in test_app.py.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from backend.services.view import ViewContext
from frontend.viewer.motion import PathClip
from frontend.viewer.recordings import Recording
from frontend.viewer.session import MODES, ViewerSession
from sim_core import get_preset
from sim_core.world.world import Side, World
from tests.frontend.viewer.headless import HeadlessViewer
from tests.frontend.viewer.view_service import wait_for

ROBOT = get_preset("paper")


def share(run_id: int, overlay_id: int | None = None) -> str:
    return f"<html>run {run_id}</html>"


@pytest.fixture
def session(server):
    with HeadlessViewer(server.get_port()):
        wait_for(server.get_clients)
        (client,) = server.get_clients().values()
        session = ViewerSession(client, "panel-one", ViewContext(sessions=None, robot_service=None), ROBOT,
                                panel_url="http://127.0.0.1:8000/panel/", share=share)  # fmt: skip
        wait_for(lambda: session.modes["simulate"].gait_note != "searching…")  # its first search restarts the climb
        yield session
        session.close()


def replay_of(run_id: int) -> Recording:
    """A short robot run, shown at a robot with walls further apart than the session's."""
    robot = dataclasses.replace(ROBOT, wall_distance=ROBOT.wall_distance + 0.1)
    time = np.linspace(0.0, 2.0, 201)
    clip = PathClip.from_body(time, 0.05 * np.sin(time), 0.2 * time)
    return Recording(run_id, "robot", f"run {run_id}", clip, robot, None, np.array([[0.5, -1, 0.1], [1.5, 1, 0.3]]))


def test_a_new_view_starts_in_simulate_mode_on_its_browsers_scene(session):
    assert session.viewer == "panel-one" and session.mode is session.modes["simulate"]
    assert session.scene.scene is session.client.scene, "drawn for this browser only"
    assert tuple(session.modes) == MODES and session.gui_mode.value == "simulate"
    assert [mode.folder.visible for mode in session.modes.values()] == [True, False, False]
    assert session.run_id is None
    assert session.modes["replay"].share is share, "its replays share through the view's files"


def test_choosing_a_mode_shows_its_gui_and_starts_the_scene_afresh(session):
    session.frame(3.0)  # the model climbs: touchdowns marked, past jumps' trails kept
    assert session.scene.touchdown_markers.count > 1
    session.scene.show_ghost(session.modes["simulate"].climb.pose_at(0.0))
    session.set_mode("live")
    assert session.mode is session.modes["live"] and session.gui_mode.value == "live"
    assert [mode.folder.visible for mode in session.modes.values()] == [False, True, False]
    assert session.scene.touchdown_markers.count == 0 and session.scene.jump_trails.count == 0
    assert not session.scene.ghost.visible
    session.gui_mode.value = "simulate"  # as the browser's dropdown sets it (its callback runs)
    assert session.mode is session.modes["simulate"]


def test_a_stored_run_goes_on_this_browsers_timeline(session):
    recording = replay_of(7)
    session.replay(7, None, recording, None)
    assert session.mode.name == "replay" and session.gui_mode.value == "replay" and session.run_id == 7
    assert session.scene.robot is recording.robot
    session.set_mode("simulate")
    assert session.scene.robot is ROBOT, "the other modes draw the session's robot"
    assert session.run_id == 7, "the run stays on the timeline"


def test_the_header_says_the_chute_the_scene_draws_the_walls_or_a_world(session):
    walls = f"walls {ROBOT.wall_distance:.2f} m apart"
    assert session.gui_header.content.endswith(f"Control panel</a> · {walls}")
    ramp = World(Side(np.array([[-1.0, 0.0], [-2.0, 2.0]]), np.array([1.0])),
                 Side(np.array([[1.0, 0.0], [1.0, 2.0]]), np.array([1.0])), "ramp")  # fmt: skip
    session.replay(7, None, dataclasses.replace(replay_of(7), world=ramp, world_mu=1.0), None)
    session.frame(0.1)
    l0 = ROBOT.leg_length
    assert session.gui_header.content.endswith(f" · world 'ramp', sides {2 * l0:.2f} m to {3 * l0:.2f} m apart")
    assert "walls" not in session.gui_header.content, "no parallel walls in a world"
    session.set_mode("simulate")
    session.frame(0.1)
    assert session.gui_header.content.endswith(f" · {walls}"), "the walls again"


def test_each_frame_draws_the_mode_and_the_readout_when_asked(session):
    simulate = session.modes["simulate"]
    session.frame(0.25)
    assert simulate.time == pytest.approx(0.25) and simulate.gui_readout.content == ""
    session.frame(0.25, readout_rate=60.0)
    assert simulate.time == pytest.approx(0.5) and simulate.gui_readout.content.startswith("**Jump** ")


def test_a_closed_view_draws_and_computes_nothing(session):
    simulate = session.modes["simulate"]
    session.close()
    assert session.closed and simulate._gait_worker._shutdown, "its gait search is stopped"
    session.frame(1.0, readout_rate=60.0)
    assert simulate.time == 0.0
    session.set_mode("live")
    session.replay(7, None, replay_of(7), None)
    assert session.mode.name == "simulate" and session.run_id is None


class Pressed:
    """A robot service that records e-stop presses and answers as the service does, unacknowledged."""

    def __init__(self):
        self.presses = 0
        self.pressed_by = None

    def estop(self, by: str | None = None) -> dict:
        self.presses += 1
        self.pressed_by = by
        return {"acknowledged": False, "reason": "the robot is not connected: nothing to send the ESTOP to"}


def test_the_views_own_page_has_an_estop_that_presses_the_services(server):
    """The 3D view on its own port had no e-stop (issue 40): with a robot service, it has one; a
    press from the browser presses the service's e-stop and says its answer."""
    robot = Pressed()
    with HeadlessViewer(server.get_port()) as browser:
        wait_for(server.get_clients)
        (client,) = server.get_clients().values()
        session = ViewerSession(client, None, ViewContext(sessions=None, robot_service=robot), ROBOT,
                                panel_url="/panel/", share=share)  # fmt: skip
        try:
            browser.set_gui("EMERGENCY STOP", True)  # the browser's click
            wait_for(lambda: robot.presses == 1)
            assert robot.pressed_by == "someone at the 3D view", "the latch says where it was pressed"
            wait_for(lambda: "E-stop sent" in session.gui_estop_said.content)
            assert "not connected" in session.gui_estop_said.content and "latched" in session.gui_estop_said.content
        finally:
            session.close()


def test_without_a_robot_service_the_view_has_no_estop(session):
    assert session.gui_estop is None
