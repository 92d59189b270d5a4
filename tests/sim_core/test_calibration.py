"""Calibration recovers a robot's true physics and servo offsets from its tracked touchdowns, says
how sure it is, and names what the data cannot tell apart."""

import math

import numpy as np
import pytest

from sim_core.calibration import PARAMETERS, calibrate
from sim_core.noise import NO_NOISE, NoiseModel
from sim_core.touchdown_series import TouchdownSeries, pitch_at
from sim_core.validation import ParameterError
from sim_core.walls import Wall
from tests.tracked_climbs import PAPER, VARIED_LEGS, TrackedClimb, Truth, tracked_climb

TRUTH = Truth.of(alpha=72.0, c_zeta=1.25, c_psi=0.8, psi0_offset_deg=(0.6, -0.8), zeta0_offset=(0.004, -0.005))
# What the issue asks calibration to reach: alpha within 2 %, the damping within 10 %, the offsets
# within 0.3 deg and 0.003 (and every value within its own 3 standard errors).
TOLERANCE = {"alpha": 0.02, "c_zeta": 0.10, "c_psi": 0.10}
OFFSET_TOLERANCE = {"psi0_offset_deg": 0.3, "zeta0_offset": 0.003}


def series_of(climb: TrackedClimb) -> TouchdownSeries:
    return TouchdownSeries.of(
        state=[td.state for td in climb.touchdowns],
        foot_height=[td.foot_height / PAPER.leg_length for td in climb.touchdowns],
        commanded=[(math.radians(p), z) for p, z in climb.controls],
        right_leg=[td.wall == Wall.RIGHT for td in climb.touchdowns],
        pitch=pitch_at([td.time for td in climb.touchdowns], climb.frames["time"], climb.frames["pitch"]),
    )


def climbs(truth: Truth, noise: NoiseModel, *, legs=VARIED_LEGS, jumps=60, seed=3) -> list[TouchdownSeries]:
    rng = np.random.default_rng(seed)
    return [series_of(tracked_climb(truth, pair, jumps=jumps, noise=noise, rng=rng)) for pair in legs]


def assert_recovered(fit, truth: Truth, *, tolerances: bool = True) -> None:
    """Every value within 3 of its standard errors of the truth, and (``tolerances``) within the issue's tolerances."""
    values = fit.to_dict()
    true = {"alpha": truth.robot.to_model().alpha, "c_zeta": truth.robot.to_model().c_zeta,
            "c_psi": truth.robot.to_model().c_psi}  # fmt: skip
    for name, relative in TOLERANCE.items():
        found, error = values["params"][name], values["stderr"][name]
        assert not tolerances or abs(found - true[name]) < relative * true[name], f"{name}: {found:.4g} vs {true[name]}"
        assert abs(found - true[name]) < 3 * error, f"{name}: {found:.4g} ± {error:.2g} vs {true[name]:.4g}"
    for name, tolerance in OFFSET_TOLERANCE.items():
        for side, truth_value in enumerate(getattr(truth.offsets, name)):
            found, error = values["params"][name][side], values["stderr"][name][side]
            assert not tolerances or abs(found - truth_value) < tolerance, (
                f"{name}[{side}]: {found:.4g} vs {truth_value}"
            )
            assert abs(found - truth_value) < 3 * error, f"{name}[{side}]: {found:.4g} ± {error:.2g} vs {truth_value}"


def test_recovers_the_truth_from_a_noisy_robot_within_its_own_errors():
    noise = NoiseModel(pitch_drift_deg=0.2)  # control, state and pitch noise; 1 mm tracker noise
    fit = calibrate(climbs(TRUTH, noise), PAPER.to_model())
    assert_recovered(fit, TRUTH)
    assert fit.touchdowns_used > 200 and fit.failed_predictions == 0
    assert fit.rms_after < 0.25 * fit.rms_before, (fit.rms_before, fit.rms_after)
    # The noise the robot really had is estimated too: 0.5 deg and 0.003 per jump on the controls.
    assert fit.noise["psi0_deg"] == pytest.approx(0.5, rel=0.25)
    assert fit.noise["zeta0"] == pytest.approx(0.003, rel=0.25)
    correlation = fit.correlation
    assert correlation.shape == (len(PARAMETERS),) * 2 and np.allclose(np.diag(correlation), 1.0)
    assert np.allclose(correlation, correlation.T)


def test_a_perfect_robot_gives_the_paper_back():
    perfect = Truth.of(alpha=PAPER.to_model().alpha, c_zeta=PAPER.to_model().c_zeta, c_psi=PAPER.to_model().c_psi,
                       psi0_offset_deg=(0, 0), zeta0_offset=(0, 0))  # fmt: skip
    fit = calibrate(climbs(perfect, NO_NOISE, jumps=40), PAPER.to_model())
    assert_recovered(fit, perfect, tolerances=False)  # the paper's light damping: 0.31 ± 0.03, near 10 % alone
    assert fit.rms_before < 0.02, "the paper's model already predicts its own robot (1 mm tracker noise)"


def test_one_gait_says_what_it_cannot_pin_down():
    # A single gait excites the model along one path: the fit must not print confident numbers.
    # With as many touchdowns as four varied gaits give, the energy's parameters (alpha, c_zeta,
    # the zeta0 offsets) come out 2.5 to 3 times less sure and confounded — the legs' zeta0 offsets
    # with each other and with c_zeta — while the psi0 offsets, which the touchdown's geometry
    # shows directly, stay about as sure. Its values stay within their own 3 errors.
    noise = NoiseModel(pitch_drift_deg=0.2)
    one = calibrate(climbs(TRUTH, noise, legs=VARIED_LEGS[:1], jumps=80), PAPER.to_model())
    varied = calibrate(climbs(TRUTH, noise, jumps=20), PAPER.to_model())
    assert one.touchdowns_used >= varied.touchdowns_used
    assert_recovered(one, TRUTH, tolerances=False)
    for name in ("alpha", "c_zeta", "zeta0_offset.left", "zeta0_offset.right"):
        assert one.stderr[name] > 2 * varied.stderr[name], (name, one.stderr[name], varied.stderr[name])
    for name in ("psi0_offset_deg.left", "psi0_offset_deg.right"):
        assert one.stderr[name] < 1.5 * varied.stderr[name], (name, one.stderr[name], varied.stderr[name])
    confounded = [pair[:2] for pair in one.confounded]
    assert ("zeta0_offset.left", "zeta0_offset.right") in confounded and varied.confounded == ()


def test_too_few_touchdowns_is_an_error_naming_the_runs():
    few = climbs(TRUTH, NO_NOISE, legs=VARIED_LEGS[:1], jumps=6)
    with pytest.raises(ParameterError) as error:
        calibrate(few, PAPER.to_model())
    assert error.value.field == "runs" and "at least 10" in str(error.value)
