"""The robustness study of a stored calibration: the robot's jumps to failure per gait beside the
calibrated model's MJTF (backend/services/robustness.py)."""

import numpy as np
import pytest

from backend import errors
from backend.schemas.worlds import WorldCreate
from backend.services import calibrations, worlds
from backend.services.robot_records import replay_run
from backend.services.robustness import robustness
from sim_core.model.errors import ParameterError
from sim_core.model.noise import NoiseModel
from sim_core.world.climb import climb_world
from sim_core.world.files import world_from_document
from tests.backend.services.test_run_prediction import GAIT, JUMPS, ROBOT, START, store_run, tracked
from tests.tracked_climbs import Truth, store_tracked_run, store_varied_runs, tracked_climb

TRUTH = Truth.of(alpha=72.0, c_zeta=1.25, c_psi=0.8, psi0_offset_deg=(0.6, -0.8), zeta0_offset=(0.004, -0.005))
FALLING_LEGS = ((30.0, 0.90), (30.0, 0.90))


@pytest.fixture
def calibrated(session):
    runs = store_varied_runs(session, TRUTH, noise=NoiseModel(), jumps=30)
    climb = tracked_climb(TRUTH, FALLING_LEGS, jumps=12, noise=NoiseModel(), rng=np.random.default_rng(1))
    fallen = store_tracked_run(session, climb, FALLING_LEGS, fell=True)
    calibrations.calibrate_runs(session, runs, name="bench")
    return runs, fallen


def test_the_robots_jumps_to_failure_stand_beside_the_models(session, calibrated):
    runs, fallen = calibrated
    study = robustness(session, "bench", [*runs, fallen, replay_run(session, fallen).id], trials=40, cap=200)
    assert study["runs"] == sorted([*runs, fallen]), "a replay counts as its robot run, once"
    assert set(study["noise"]) >= {"psi0_deg", "zeta0", "velocity", "pitch_drift_deg", "asymmetry_psi0_deg"}
    assert study["noise"]["asymmetry_psi0_deg"] < 0, "the right leg's offset relative to the left's"
    gaits = {tuple(map(tuple, row["controls"])): row for row in study["gaits"]}
    assert len(gaits) == 4, "four gaits; the fallen run shares the symmetric one"
    symmetric = gaits[FALLING_LEGS]
    assert (symmetric["robot"]["tries"], symmetric["robot"]["failures"]) == (2, 1)
    assert symmetric["robot"]["mjtf"] == symmetric["robot"]["jumps"]
    for row in gaits.values():
        model = row["model"]
        assert model["tries"] == 40 and model["cap"] == 200 and 0 <= model["capped"] <= 40
        low, high = model["ci95"]
        assert model["mjtf"] is None or low <= model["mjtf"] <= high


def test_by_default_the_study_compares_the_runs_the_preset_came_from(session, calibrated):
    runs, _ = calibrated
    assert robustness(session, "bench", trials=5, cap=50)["runs"] == sorted(runs)


def test_what_the_study_cannot_compare_says_why(session, calibrated, make_run):
    with pytest.raises(errors.NotFound, match="preset nothing"):
        robustness(session, "nothing", trials=5, cap=50)
    with pytest.raises(errors.Conflict, match="robot's runs"):
        robustness(session, "bench", [make_run().id], trials=5, cap=50)
    for field, options in (("trials", {"trials": 0, "cap": 50}), ("cap", {"trials": 5, "cap": 10**6})):
        with pytest.raises(ParameterError) as error:
            robustness(session, "bench", **options)
        assert error.value.field == field
    world = worlds.create(session, WorldCreate(name="narrowing chute", named="narrowing"))
    climb = climb_world(ROBOT.to_model(), world_from_document(world.world, ROBOT.leg_length), GAIT, START, JUMPS)
    in_world = store_run(session, tracked(climb), world.id).id
    with pytest.raises(ParameterError, match=f"run {in_world} climbed world {world.id}") as error:
        robustness(session, "bench", [in_world], trials=5, cap=50)
    assert error.value.field == "runs"
