"""History's touchdowns view of a run in a stored world (backend/services/calibrations.py,
``touchdown_predictions``): each touchdown predicted by the model's jump in that world from the one
before as it was met, not by the parallel-walls map; a run without a world as it always was; and
calibration, whose fit is the map's, refuses a run in a world by name.

The touchdowns are sim_core's own climb in the narrowing world (tests/backend/services/
test_run_prediction.py builds them), first seen on the right side above the floor."""

import numpy as np
import pytest

from backend.schemas.worlds import WorldCreate
from backend.services import calibrations, worlds
from sim_core.calibration.calibrate import one_jump_predictions
from sim_core.calibration.world_jumps import world_one_jump_predictions
from sim_core.model.controls import NO_OFFSETS
from sim_core.model.errors import ParameterError
from sim_core.model.noise import NoiseModel
from sim_core.world.climb import climb_world
from sim_core.world.files import world_from_document
from tests.backend.services.test_run_prediction import GAIT, JUMPS, ROBOT, START, store_run, tracked
from tests.tracked_climbs import Truth, store_varied_runs

CHANNELS = ("xdot", "ydot", "rise")
TIGHT = 1e-9
TRUTH = Truth.of(alpha=72.0, c_zeta=1.25, c_psi=0.8, psi0_offset_deg=(0.6, -0.8), zeta0_offset=(0.004, -0.005))


@pytest.fixture
def narrowing(session):
    """The narrowing world stored (for the paper robot's d_hat): its row's id, name and world in l0."""
    stored = worlds.create(session, WorldCreate(name="narrowing chute", named="narrowing"))
    return stored.id, stored.name, world_from_document(stored.world, ROBOT.leg_length)


def table(comparison, model: str) -> np.ndarray:
    """Shape (touchdowns, 3): ``model``'s (or "measured") channels of each compared touchdown."""
    return np.array([[getattr(getattr(row, model), channel) for channel in CHANNELS] for row in comparison.touchdowns],
                    dtype=float)  # fmt: skip


def test_a_run_in_a_world_is_predicted_jump_by_jump_in_that_world(session, narrowing):
    world_id, name, chute = narrowing
    climb = climb_world(ROBOT.to_model(), chute, GAIT, START, JUMPS)
    assert climb.failure is None
    touchdowns = tracked(climb)
    in_world = store_run(session, touchdowns, world_id)
    between_walls = store_run(session, touchdowns, None)

    found = calibrations.touchdown_predictions(session, in_world.id, preset=None)
    assert found.world is not None and (found.world.id, found.world.name) == (world_id, name)
    assert [row.index for row in found.touchdowns] == list(range(1, len(touchdowns)))
    measured = table(found, "measured")
    np.testing.assert_allclose(table(found, "paper"), measured, rtol=0, atol=TIGHT, err_msg="the climb's own jumps")
    assert np.abs(table(found, "paper_residual")).max() < TIGHT
    assert max(getattr(found.rms["paper"], channel) for channel in CHANNELS) < TIGHT

    walls = calibrations.touchdown_predictions(session, between_walls.id, preset=None)
    assert walls.world is None, "parallel walls: no world named"
    np.testing.assert_allclose(table(walls, "measured"), measured, rtol=0, atol=0)
    off = np.abs(table(walls, "paper") - measured).max()
    assert off > 0.01, f"the map's walls are not the world's ({off:.4f})"


def test_a_run_without_a_world_is_predicted_as_it_always_was(session, narrowing):
    """The parallel-walls map's one-jump predictions, as sim_core.calibration gives them."""
    _world_id, _name, chute = narrowing
    run = store_run(session, tracked(climb_world(ROBOT.to_model(), chute, GAIT, START, JUMPS)), None)
    series = calibrations.touchdown_series(session, run, ROBOT)
    expected = one_jump_predictions(series, {"paper": (ROBOT.to_model(), NO_OFFSETS)})
    found = calibrations.touchdown_predictions(session, run.id, preset=None)
    assert found.world is None and "world" in found.model_dump()
    assert table(found, "paper") == pytest.approx(expected["paper"], abs=1e-15)
    assert table(found, "measured") == pytest.approx(expected["measured"], abs=1e-15)


def test_a_calibrated_model_predicts_in_the_world_too(session, narrowing):
    """With a stored calibration chosen, its model (and its legs' offsets) jumps in the world as well."""
    world_id, _name, chute = narrowing
    fitted = store_varied_runs(session, TRUTH, noise=NoiseModel(pitch_drift_deg=0.2), jumps=30)
    calibrations.calibrate_runs(session, fitted, name="table.v1")
    run = store_run(session, tracked(climb_world(ROBOT.to_model(), chute, GAIT, START, JUMPS)), world_id)
    found = calibrations.touchdown_predictions(session, run.id, preset="table.v1")
    assert found.world is not None and found.world.id == world_id and found.preset == "table.v1"
    calibrated = table(found, "calibrated")
    assert np.isfinite(calibrated).all() and set(found.rms) == {"paper", "calibrated"}
    robot, offsets = calibrations.preset_params(session, "table.v1")
    assert offsets.psi0_offset_deg != (0.0, 0.0), "the fitted legs' offsets"
    series = calibrations.touchdown_series(session, run, ROBOT)
    expected = world_one_jump_predictions(series, {"calibrated": (robot.to_model(), offsets)}, chute)["calibrated"]
    np.testing.assert_allclose(calibrated, expected, rtol=0, atol=1e-15, err_msg="the preset's model, in the world")
    walls = one_jump_predictions(series, {"calibrated": (robot.to_model(), offsets)})["calibrated"]
    assert np.abs(walls - calibrated).max() > 0.01, "not the calibrated model between parallel walls"


def test_calibration_refuses_a_run_in_a_world_naming_it(session, narrowing):
    world_id, _name, chute = narrowing
    run = store_run(session, tracked(climb_world(ROBOT.to_model(), chute, GAIT, START, JUMPS)), world_id)
    with pytest.raises(ParameterError) as refused:
        calibrations.calibrate_runs(session, [run.id], name="in-a-world")
    assert refused.value.field == "runs"
    assert f"run {run.id} climbed world {world_id}" in str(refused.value) and "parallel walls" in str(refused.value)
