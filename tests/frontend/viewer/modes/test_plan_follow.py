"""Simulate mode following a plan in a stored world (frontend/viewer/modes/plan_follow.py), in the
service with a headless browser: the world drawn in place of the walls, the followed path's
touchdowns follow_plan's, each passed touchdown's target marked hit or missed, the next one aimed
at, and the stream within its budget."""

import time

import numpy as np

from frontend.viewer.modes.plan_follow import NO_WORLD
from sim_core.model.noise import NoiseModel
from sim_core.planning.follow import follow_plan
from sim_core.planning.launch import start_velocity
from sim_core.planning.planner import plan_climb
from sim_core.world.files import world_from_document
from tests.frontend.viewer.view_service import wait_for

GOAL = 1.2  # [m]
BUDGET = 100_000  # [B/s] the stream's budget per browser


def test_a_plan_is_followed_in_a_stored_world_within_the_stream_budget(service, browsers):
    client, auth, _view = service
    world = client.post("/api/v1/worlds", json={"name": "holds", "random": {"seed": 3}}, headers=auth).json()
    browser, session = browsers()
    simulate = session.modes["simulate"]
    follow = simulate.follow
    follow.refresh()
    choice = f"{world['id']}: holds"
    assert follow.gui_world.options == (NO_WORLD, choice)
    follow.gui_world.value, follow.gui_goal.value, follow.gui_seed.value = choice, GOAL, 4
    follow.request()
    wait_for(lambda: follow.active or "Cannot" in follow.note, timeout=120)
    assert follow.active, follow.note
    # the path is follow_plan's trial of that seed (its touchdowns: test_followed_path.py)
    robot = session.robot
    model, goal = robot.to_model(), GOAL / robot.leg_length
    stored = world_from_document(world["world"], robot.leg_length)
    plan = plan_climb(model, stored, goal, start_velocity(model), noise=NoiseModel(), seed=4)
    outcome = follow_plan(model, stored, plan, goal, NoiseModel(), 4)
    path = follow.path
    assert (path.reached, path.jumps, path.replans) == (outcome.reached, outcome.jumps, outcome.replans)
    # played by the view's own loop, in real time, as a browser gets it
    sent, started = browser.bytes, time.monotonic()
    end = float(follow.recording.touchdowns[-1, 0])
    wait_for(lambda: follow.time >= end, timeout=60)
    time.sleep(0.2)
    rate = (browser.bytes - sent) / (time.monotonic() - started)
    print(f"stream: {rate / 1000:.1f} kB/s over {end:.1f} s, {len(follow.path.touchdown_times)} touchdowns")
    assert rate < BUDGET, f"{rate / 1000:.0f} kB/s over {end:.1f} s of the climb"
    scene = session.scene
    assert scene.world is follow.recording.world and not any(wall.visible for wall in scene.walls)
    assert scene.touchdown_markers.count == len(path.touchdown_times)
    aimed = int(np.count_nonzero(~np.isnan(path.aims[:, 0])))
    assert scene.targets.count == aimed > 1
    hit_colours = [tuple(node.color) for node in scene.targets.nodes[: scene.targets.count]]
    assert hit_colours.count((40, 200, 70)) == int(path.hits.sum())
    readout = simulate.readout(60.0)
    assert "footholds hit" in readout and ("reached the goal" in readout or "failed" in readout), readout
    # back to the sliders: the parallel walls again
    follow.gui_world.value = NO_WORLD
    follow.request()
    session.frame(1.0 / 60.0)
    assert not follow.active and scene.world is None and all(wall.visible for wall in scene.walls)
