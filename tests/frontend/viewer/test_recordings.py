"""Recordings (frontend/viewer/recordings.py): what a recording's frame shows, as the replay and the
shared file both take it (touchdowns passed, the trail of the jump under way), and stored runs
loaded through the service. (Robot and replay runs are loaded in test_share.py's fixture.)"""

import numpy as np
from numpy.testing import assert_array_equal

from frontend.viewer.motion import PathClip
from frontend.viewer.recordings import MAX_TRAIL_SECONDS, Recording, load_recording
from sim_core import get_preset
from tests.frontend.viewer.view_service import RUN

ROBOT = get_preset("paper")
TIME = np.round(np.arange(0.0, 20.0, 0.01), 2)  # tracker frames at 100 Hz for 20 s
CLIP = PathClip.from_body(TIME, np.sin(TIME), 0.1 * TIME)
TOUCHDOWNS = np.array([[1.0, -1, 0.05], [2.0, 1, 0.15]])


def _recording(touchdowns=TOUCHDOWNS) -> Recording:
    return Recording(1, "robot", "run 1", CLIP, get_preset("paper"), None, touchdowns)


def test_the_trail_runs_from_the_last_touchdown_passed():
    recording = _recording()
    assert recording.touchdowns_until(np.array([0.5, 1.0, 1.5, 2.5])).tolist() == [0, 1, 1, 2]
    assert recording.trail_span(0.5) == (0, 51), "before the first touchdown: from the start"
    assert recording.trail_span(1.5) == (100, 151), "from the touchdown at 1.0 s (its sample) to now"
    trail = recording.trail(1.5)
    assert_array_equal(trail, np.column_stack([CLIP.x[100:151:3], CLIP.y[100:151:3]]))
    assert_array_equal(recording.jump_trail(1), CLIP.body_until(2.0, since=1.0)[::3])
    lo, hi = recording.trail_span(np.array([0.5, 1.5]))
    assert (lo.tolist(), hi.tolist()) == ([0, 100], [51, 151]), "many instants at once, the same"


def test_without_touchdowns_the_trail_reaches_back_a_few_seconds_at_most():
    recording = _recording(np.zeros((0, 3)))
    lo, hi = recording.trail_span(12.0)
    assert TIME[hi - 1] == 12.0 and TIME[lo] == 12.0 - MAX_TRAIL_SECONDS
    assert recording.trail_span(3.0) == (0, 301)


def test_recordings_put_sim_runs_between_the_walls(service):
    client, auth, view = service
    run = client.post("/api/v1/runs", json=RUN | {"trajectory_rate": 200}, headers=auth).json()
    recording = load_recording(view.context.sessions, run["id"])
    half = 0.5 * ROBOT.wall_distance
    assert set(np.unique(recording.touchdowns[:, 1])) == {-1, 1}
    stance_feet = recording.clip.foot_x[recording.clip.phase == 0]
    assert np.allclose(np.abs(stance_feet), half), "stance feet are on the walls"
    assert np.all(np.abs(recording.clip.x) < half)


def test_a_run_in_a_world_is_replayed_in_its_world(service):
    """Its world is read and carried (drawn in place of the walls); its stored path, or one simulated
    again in that world (never between parallel walls), puts each stance foot on the world's side."""
    client, auth, view = service
    world = client.post("/api/v1/worlds", json={"name": "replayed", "named": "staircase"}, headers=auth).json()
    body = RUN | {"world_id": world["id"], "start": {"xdot": -1.0, "ydot": 0.5}}
    stored = client.post("/api/v1/runs", json=body | {"trajectory_rate": 60}, headers=auth).json()
    again = client.post("/api/v1/runs", json=body, headers=auth).json()
    with_path, simulated = (load_recording(view.context.sessions, run["id"]) for run in (stored, again))
    for recording in (with_path, simulated):
        assert recording.world is not None and recording.world.name == "replayed"
        assert f"world {world['id']}" in recording.label
        l0, clip = recording.robot.leg_length, recording.clip
        stance = clip.phase == 0
        wall_x = [recording.world.side("left" if wall < 0 else "right").x_at(y / l0) * l0
                  for wall, y in zip(clip.leg_wall[stance], clip.foot_y[stance], strict=True)]  # fmt: skip
        np.testing.assert_allclose(clip.foot_x[stance], wall_x, atol=1e-9)
        assert recording.touchdown_x is not None and len(recording.touchdown_x) == len(recording.touchdowns) >= 2
    np.testing.assert_allclose(simulated.clip.y, with_path.clip.y, atol=1e-9)
    parallel = 0.5 * ROBOT.wall_distance
    assert not np.allclose(np.abs(with_path.touchdown_x), parallel), "not the parallel walls' feet"


def _stored(**changes):
    from backend.services.view import StoredPath

    base = {"run_id": 7, "kind": "robot", "model": {}, "controls": [[35.0, 0.85], [35.0, 0.85]],
            "start_state": [-0.9, -0.2], "jumps": 15, "path": None, "touchdowns": [], "jumps_completed": 4,
            "climb": 1.111}  # fmt: skip
    return StoredPath(**(base | changes))


def test_a_share_files_description_says_how_the_run_was_driven_and_how_it_ended():
    """History lists each run's loop, controller, target and ending; its share file says the same."""
    from frontend.viewer.recordings import describe

    stopped = describe(_stored(status="failed", end_reason="e-stop", loop="closed", controller="pid", target=0.55))
    assert "; closed loop (pid, target 0.55 m); ended: e-stop; climb 1.111 l0." in stopped, stopped
    open_loop = describe(_stored(status="done", end_reason="jumps done", loop="open"))
    assert "; open loop; ended: jumps done;" in open_loop, open_loop
    simulated = describe(_stored(kind="sim", status="done", loop="open"))
    assert "loop" not in simulated and "ended" not in simulated, "a simulation's ending is its failure code"
