"""Calibrations in the store: stored robot runs fitted, kept as a named preset with its provenance,
used by name; wrong runs and names refused with what to do."""

import socket

import numpy as np
import pytest

from backend import errors
from backend.repositories import calibrations as stored_presets
from backend.repositories import runs as run_store
from backend.services import calibrations
from backend.services.robot_records import replay_run
from sim_core.model.errors import ParameterError
from sim_core.model.noise import NO_NOISE, NoiseModel
from tests.tracked_climbs import PAPER, Truth, store_varied_runs

TRUTH = Truth.of(alpha=72.0, c_zeta=1.25, c_psi=0.8, psi0_offset_deg=(0.6, -0.8), zeta0_offset=(0.004, -0.005))
VIRTUAL_NOISE = NoiseModel()
JUMPS = 60  # per live run: four runs, about 200 touchdown pairs
VIRTUAL_SPEED = 25.0  # open-loop runs: the PC only records, so faster than real time changes nothing they record


@pytest.fixture
def robot_runs(session) -> list[int]:
    return store_varied_runs(session, TRUTH, noise=NoiseModel(pitch_drift_deg=0.2), jumps=40)


def test_a_calibration_is_stored_as_a_preset_with_its_provenance(session, robot_runs):
    payload = calibrations.calibrate_runs(session, robot_runs, name="table-2026-12")
    assert set(payload) >= {"params", "stderr", "correlation", "touchdowns_used", "rms_residual_before",
                            "rms_residual_after", "unidentifiable", "confounded", "noise", "preset", "outliers",
                            "cut_at_fall", "noise_pairs"}  # fmt: skip
    assert payload["cut_at_fall"] == [], "none of these runs fell"
    assert abs(payload["params"]["alpha"] - 72.0) < 3 * payload["stderr"]["alpha"]
    assert payload["rms_residual_after"] < 0.3 * payload["rms_residual_before"]
    assert len(payload["correlation"]) == 7 and payload["touchdowns_used"] > 100
    provenance = payload["preset"]
    assert (provenance["name"], provenance["base"], provenance["runs"]) == ("table-2026-12", "paper", robot_runs)
    assert provenance["code_version"] and provenance["created_at"]

    robot, offsets = calibrations.preset_params(session, "table-2026-12")
    assert robot.to_model().alpha == pytest.approx(payload["params"]["alpha"])
    assert (robot.mass, robot.leg_length, robot.wall_distance) == (PAPER.mass, PAPER.leg_length, PAPER.wall_distance)
    assert list(offsets.psi0_offset_deg) == payload["params"]["psi0_offset_deg"]
    assert calibrations.preset_payload(calibrations.get_stored_preset(session, "table-2026-12")) == payload
    assert calibrations.preset_params(session, "paper") == (PAPER, calibrations.NO_OFFSETS)


def test_a_run_that_fell_is_cut_before_its_fall_and_named_in_the_report(session, robot_runs):
    from tests.tracked_climbs import VARIED_LEGS, store_tracked_run, tracked_climb

    legs = VARIED_LEGS[1]
    climb = tracked_climb(TRUTH, legs, jumps=30, noise=NoiseModel(pitch_drift_deg=0.2), rng=np.random.default_rng(7))
    fallen = store_tracked_run(session, climb, legs, fell=True)
    assert calibrations.run_fell(run_store.get_run(session, fallen))
    assert not calibrations.run_fell(run_store.get_run(session, robot_runs[0]))
    replay = replay_run(session, fallen).id  # a replay fell as its robot run did
    assert calibrations.touchdown_series(session, run_store.get_run(session, replay), PAPER).fell
    runs = [*robot_runs[:3], replay]
    payload = calibrations.calibrate_runs(session, runs, name="with-a-fall")
    assert payload["cut_at_fall"] == [{"series": 3, "touchdown": len(climb.touchdowns) - 1, "run_id": replay}]
    assert all(outlier["run_id"] == runs[outlier["series"]] for outlier in payload["outliers"])
    assert payload["noise_pairs"] == payload["touchdowns_used"] - len(payload["outliers"])
    assert abs(payload["params"]["alpha"] - 72.0) < 3 * payload["stderr"]["alpha"]


def test_a_replay_calibrates_like_its_robot_run(session, robot_runs):
    replays = [replay_run(session, run_id).id for run_id in robot_runs]
    from_runs = calibrations.calibrate_runs(session, robot_runs, name="from-runs")
    from_replays = calibrations.calibrate_runs(session, replays, name="from-replays")
    assert _flat(from_replays["params"]) == pytest.approx(_flat(from_runs["params"]))


def test_what_cannot_be_calibrated_says_why(session, robot_runs, make_run):
    simulated = make_run()
    with pytest.raises(errors.Conflict, match="robot and replay runs"):
        calibrations.calibrate_runs(session, [robot_runs[0], simulated.id], name="x")
    with pytest.raises(errors.NotFound, match="run 999"):
        calibrations.calibrate_runs(session, [999], name="x")
    for name in ("paper", "", "-x", "a b", "x" * 65):
        with pytest.raises(ParameterError) as error:
            calibrations.calibrate_runs(session, robot_runs, name=name)
        assert error.value.field == "name"
    calibrations.calibrate_runs(session, robot_runs[:2], name="once")
    with pytest.raises(errors.Conflict, match="exists"):
        calibrations.calibrate_runs(session, robot_runs[:2], name="once")
    with pytest.raises(ParameterError, match="known presets: paper, once"):
        calibrations.preset_params(session, "nothing")


def test_a_run_too_short_to_fit_is_a_parameter_error(session):
    [run_id, *_] = store_varied_runs(session, TRUTH, noise=NO_NOISE, jumps=5)
    with pytest.raises(ParameterError) as error:
        calibrations.calibrate_runs(session, [run_id], name="short")
    assert error.value.field == "runs"
    assert stored_presets.all_presets(session) == []


def test_a_deleted_preset_is_gone(session, robot_runs):
    calibrations.calibrate_runs(session, robot_runs[:2], name="old")
    calibrations.delete_preset(session, "old")
    with pytest.raises(errors.NotFound):
        calibrations.get_stored_preset(session, "old")


def _flat(params: dict) -> list[float]:
    return [params["alpha"], params["c_zeta"], params["c_psi"], *params["psi0_offset_deg"], *params["zeta0_offset"]]


@pytest.mark.slow
def test_calibration_recovers_the_virtual_robots_truth(session, service):
    """The honest test: live runs of a virtual robot whose physics and servos differ from the paper
    (parkour robot-sim --alpha ... --psi0-offset-deg L R --zeta0-offset L R --noise on), recorded
    by the robot service over the radio and the tracker, then fitted."""
    from backend.robot.virtual import VirtualRobot
    from backend.schemas import LegIn, RobotConnect, RobotRunCreate
    from tests.helpers import free_port
    from tests.tracked_climbs import VARIED_LEGS

    port = free_port(socket.SOCK_DGRAM)
    robot = VirtualRobot(tracker_to=("127.0.0.1", port), robot=TRUTH.robot, leg_offsets=TRUTH.offsets,
                         noise=VIRTUAL_NOISE, speed=VIRTUAL_SPEED, seed=5).start()  # fmt: skip
    try:
        service.connect(RobotConnect(url=robot.url, tracker_port=port))
        runs = []
        for legs in VARIED_LEGS:
            if service.status()["state"] != "disarmed":
                service.reset()
            service.start_run(RobotRunCreate(controls=[LegIn(psi0_deg=p, zeta0=z) for p, z in legs], jumps=JUMPS))
            assert not service.wait_run(60.0).active, "the live run did not end"
            runs.append(service.status()["run"]["stored_run_id"])
    finally:
        service.disconnect()
        robot.stop()

    fit = calibrations.calibrate_runs(session, runs, name="virtual")
    # Measured (seed 5, docs/calibration.md): alpha 72.07 ± 0.52, c_zeta 1.234 ± 0.040, c_psi 0.789 ±
    # 0.019, psi0 offsets 0.64 / -0.67 ± 0.09 deg, zeta0 offsets 0.0047 / -0.0041 ± 0.0008, from about
    # 200 touchdown pairs. Held to the tolerances and to 3 standard errors.
    truth = {"alpha": (72.0, 0.02 * 72.0), "c_zeta": (1.25, 0.125), "c_psi": (0.8, 0.08)}
    for name, (value, tolerance) in truth.items():
        found, error = fit["params"][name], fit["stderr"][name]
        assert abs(found - value) < min(tolerance, 3 * error), (name, found, error)
    for name, tolerance in (("psi0_offset_deg", 0.3), ("zeta0_offset", 0.003)):
        for side, value in enumerate(getattr(TRUTH.offsets, name)):
            found, error = fit["params"][name][side], fit["stderr"][name][side]
            assert abs(found - value) < min(tolerance, 3 * error), (name, side, found, error)
    assert fit["noise"]["psi0_deg"] == pytest.approx(0.5, rel=0.25), "the robot's control noise, estimated"
