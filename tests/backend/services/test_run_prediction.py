"""A tracked run's ``results.prediction`` in the chute it climbed (backend/services/run_prediction.py):
in a stored world the model's climb there from the first detected touchdown (here on the right
side, above the floor), made of sim_core's own climb in that world so the prediction must give its
touchdowns back; between parallel walls the Poincaré map's, unchanged; a climb that fails says so
as the map does."""

import datetime
import math

import numpy as np
import pytest

from backend.repositories import runs as run_store
from backend.robot.touchdown import Touchdown, detect_touchdowns
from backend.robot.tracker import Calibration
from backend.schemas import LegIn, RobotRunCreate
from backend.schemas.worlds import WorldCreate
from backend.services import worlds
from backend.services.mcap_export import METADATA_NAME
from backend.services.robot_plans import sides_at
from backend.services.robot_records import fold_journal, open_robot_run, replay_run
from backend.store.models import RunJournal
from experiments.manifest import json_safe
from sim_core import ControlSchedule, get_preset, iterate_map
from sim_core.model.walls import Wall
from sim_core.world.climb import climb_world
from sim_core.world.files import world_from_document
from sim_core.world.trajectory import simulate_world_trajectory
from tests.backend.services.test_mcap_export import exported, read

ROBOT = get_preset("paper")
L0 = ROBOT.leg_length
LEGS = ((30.0, 0.87), (30.0, 0.9))
GAIT = ControlSchedule.from_degrees(LEGS)
REQUEST = RobotRunCreate(controls=[LegIn(psi0_deg=p, zeta0=z) for p, z in LEGS], jumps=8)
START = (-1.0, 0.5)  # the climb's touchdown 0, on the left side at the floor; the robot detects from touchdown 1
JUMPS = 7
TIGHT = 1e-9
DETECTED = 2e-3  # [sqrt(g l0), l0] touchdowns detected from frames in a world with sloping sides
# Two vertical sides d_hat apart without grip (mu 0) up to 20 l0: the first stance slips.
ICE = {"units": "l0", "left": {"points": [[-1.21, 0.0], [-1.21, 20.0]], "mu": [0.0]},
       "right": {"points": [[1.21, 0.0], [1.21, 20.0]], "mu": [0.0]}}  # fmt: skip


@pytest.fixture
def narrowing(session):
    """The narrowing world stored (for the paper robot's d_hat): its row's id, name and world in l0."""
    stored = worlds.create(session, WorldCreate(name="narrowing chute", named="narrowing"))
    return stored.id, stored.name, world_from_document(stored.world, L0)


def tracked(climb) -> list[Touchdown]:
    """``climb``'s touchdowns 1.. as the tracker would detect them: wall, section state flipped to
    it, body and foot in metres (the feet where the gait's legs put them)."""
    touchdowns = []
    for k in range(1, climb.states.shape[0]):
        x, y, xdot, ydot = climb.states[k]
        wall = Wall.LEFT if climb.sides[k] == 0 else Wall.RIGHT
        leg = GAIT[k]
        touchdowns.append(Touchdown(
            index=k - 1, time=0.3 * k, wall=wall, state=(-int(wall) * xdot, ydot), body_height=y * L0,
            foot_height=(y - leg.zeta0 * math.sin(leg.psi0)) * L0, poses_fitted=8, body_x=x * L0,
        ))  # fmt: skip
    return touchdowns


def store_run(session, touchdowns: list[Touchdown], world_id: int | None, frames: dict | None = None):
    """A robot run in ``world_id`` journaled with ``touchdowns`` (detected touchdown k under the
    gait's row k + 1) and ``frames`` (none: no tracker frames), folded ``done``: the run."""
    run_id = open_robot_run(session, REQUEST, ROBOT, Calibration(), world_id=world_id)
    created = run_store.get_run(session, run_id).created_at
    frames = frames or {"time": [], "x": [], "y": [], "pitch": []}
    entry = {
        "frames": frames,
        "touchdowns": [{"touchdown": td.to_dict(), "control": list(LEGS[(td.index + 1) % 2])} for td in touchdowns],
        "commands": [], "telemetry": [], "transitions": [], "tracker": {"dropped": 0, "loss": 0.0},
    }  # fmt: skip
    session.add(RunJournal(run_id=run_id, data=json_safe(entry), written_at=created + datetime.timedelta(seconds=1)))
    session.commit()
    return fold_journal(session, run_id, status="done", end_reason="jumps done", disarm="confirmed", robot=ROBOT)


def flipped(climb) -> np.ndarray:
    """``climb``'s touchdowns' ``(xdot, ydot)`` flipped to the left wall, as a tracked touchdown's."""
    return np.column_stack([np.where(climb.sides == 0, 1.0, -1.0) * climb.states[:, 2], climb.states[:, 3]])


def test_a_run_in_a_world_is_predicted_by_the_climb_there_and_one_without_by_the_map(session, narrowing):
    world_id, name, chute = narrowing
    climb = climb_world(ROBOT.to_model(), chute, GAIT, START, JUMPS)
    assert climb.failure is None
    touchdowns = tracked(climb)
    assert touchdowns[0].wall == Wall.RIGHT and touchdowns[0].foot_height > 0.1, "first seen on the right, in the air"

    in_world = store_run(session, touchdowns, world_id).results
    prediction = in_world["prediction"]
    assert prediction["world"] == {"id": world_id, "name": name} and prediction["failure"] is None
    assert np.array(prediction["states"]) == pytest.approx(flipped(climb)[1:], abs=TIGHT), "the climb's touchdowns"
    assert np.array(prediction["states"]) == pytest.approx(np.array(in_world["states"]), abs=TIGHT)
    assert prediction["rises"] == pytest.approx(in_world["rises"], abs=TIGHT), "in l0, foot to foot, as measured"

    between_walls = store_run(session, touchdowns, None).results["prediction"]
    schedule = ControlSchedule.from_degrees([LEGS[(k + 1) % 2] for k in range(len(touchdowns))])
    assert between_walls == iterate_map(ROBOT.to_model(), schedule, touchdowns[0].state, JUMPS - 1).to_dict()
    assert "world" not in between_walls, "parallel walls: the prediction as it always was"
    off = np.abs(np.array(between_walls["states"]) - np.array(prediction["states"])).max()
    assert off > 0.01, f"the map's walls are not the world's ({off:.4f})"


def test_a_world_climb_that_fails_says_so_as_the_map_does(session, narrowing):
    _world_id, _name, chute = narrowing
    touchdowns = tracked(climb_world(ROBOT.to_model(), chute, GAIT, START, JUMPS))
    ice = worlds.create(session, WorldCreate(name="ice", world=ICE))
    prediction = store_run(session, touchdowns, ice.id).results["prediction"]
    assert prediction["failure"] == {"code": "slip", "jump": 1} and prediction["world"]["name"] == "ice"
    assert prediction["states"] == [list(touchdowns[0].state)] and prediction["rises"] == []


def test_a_replay_of_a_run_in_a_world_predicts_its_touchdowns_in_that_world(session, narrowing):
    world_id, _name, chute = narrowing
    path, climb = simulate_world_trajectory(ROBOT.to_model(), chute, GAIT, START, JUMPS,
                                            sample_rate=100.0 * ROBOT.scales.time)  # fmt: skip
    path = path.to_si(ROBOT)
    frames = {"time": path.time, "x": path.x, "y": path.y}
    touchdowns = detect_touchdowns(*frames.values(), ROBOT, lambda k: GAIT[k + 1], side_at=sides_at(chute, ROBOT))
    assert len(touchdowns) == JUMPS - 1 and touchdowns[0].wall == Wall.RIGHT  # the path ends at the last touchdown
    source = store_run(session, touchdowns, world_id, {**frames, "pitch": np.full(path.time.size, math.nan)})
    replay = replay_run(session, source.id, ROBOT).results
    prediction = replay["prediction"]
    assert prediction["world"]["id"] == world_id and prediction["failure"] is None
    # The detector meets a sloping side where the foot is at the frame it sees, not where it will
    # be at the crossing: its touchdowns are the climb's to a few 1e-4, and so is the prediction.
    assert np.array(prediction["states"]) == pytest.approx(flipped(climb)[1:JUMPS], abs=DETECTED)
    assert np.array(prediction["states"]) == pytest.approx(np.array(replay["states"]), abs=DETECTED)
    assert prediction["rises"] == pytest.approx(replay["rises"], abs=DETECTED)


def test_the_recording_says_which_model_predicted(session, narrowing):
    """The MCAP export's /model/prediction is the world's prediction, its metadata naming the model."""
    world_id, name, chute = narrowing
    touchdowns = tracked(climb_world(ROBOT.to_model(), chute, GAIT, START, JUMPS))
    models = {}
    for world in (world_id, None):
        run = store_run(session, touchdowns, world)
        _summary, metadata, messages, _every = read(exported(session, run.id)[0])
        predicted = [m["state"] for topic, _s, _t, m in messages if topic == "/model/prediction"]
        assert predicted == run.results["prediction"]["states"]
        models[world] = metadata[METADATA_NAME]["prediction_model"]
    assert models == {world_id: f"the model's climb in world {world_id} ({name})",
                      None: "the Poincaré map between parallel walls"}  # fmt: skip
