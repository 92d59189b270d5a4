"""Calibration recovers a robot's true physics and servo offsets from its tracked touchdowns, says
how sure it is, and names what the data cannot tell apart; a run that fell or a wild touchdown
does not ruin it (issue 24)."""

import math
from dataclasses import replace

import numpy as np
import pytest

from sim_core.calibration.calibrate import OUTLIER_SIGMAS, calibrate
from sim_core.calibration.fit import PARAMETERS
from sim_core.calibration.touchdown_series import Pairs, TouchdownSeries, pitch_at
from sim_core.model.noise import NO_NOISE, NoiseModel
from sim_core.model.validation import ParameterError
from sim_core.model.walls import Wall
from tests.tracked_climbs import PAPER, VARIED_LEGS, TrackedClimb, Truth, tracked_climb

TRUTH = Truth.of(alpha=72.0, c_zeta=1.25, c_psi=0.8, psi0_offset_deg=(0.6, -0.8), zeta0_offset=(0.004, -0.005))
# What the issue asks calibration to reach: alpha within 2 %, the damping within 10 %, the offsets
# within 0.3 deg and 0.003 (and every value within its own 3 standard errors).
TOLERANCE = {"alpha": 0.02, "c_zeta": 0.10, "c_psi": 0.10}
OFFSET_TOLERANCE = {"psi0_offset_deg": 0.3, "zeta0_offset": 0.003}


def series_of(climb: TrackedClimb, *, fell: bool = False) -> TouchdownSeries:
    return TouchdownSeries.of(
        state=[td.state for td in climb.touchdowns],
        foot_height=[td.foot_height / PAPER.leg_length for td in climb.touchdowns],
        commanded=[(math.radians(p), z) for p, z in climb.controls],
        right_leg=[td.wall == Wall.RIGHT for td in climb.touchdowns],
        pitch=pitch_at([td.time for td in climb.touchdowns], climb.frames["time"], climb.frames["pitch"]),
        fell=fell,
    )


def climbs(truth: Truth, noise: NoiseModel, *, legs=VARIED_LEGS, jumps=60, seed=3) -> list[TouchdownSeries]:
    """Tracked climbs of ``legs``; one that ended before ``jumps`` fell (a finished climb detects at
    least ``jumps - 1`` touchdowns: the first, from the floor, has no flight before it)."""
    rng = np.random.default_rng(seed)
    found = [tracked_climb(truth, pair, jumps=jumps, noise=noise, rng=rng) for pair in legs]
    return [series_of(climb, fell=len(climb.touchdowns) < jumps - 1) for climb in found]


def assert_recovered(fit, truth: Truth, *, tolerances: bool = True, damping: bool = True) -> None:
    """Every value within 3 of its standard errors of the truth, and (``tolerances``) within the issue's
    tolerances (``damping``: the damping's 10 % too, issue 16's; issue 24 asks for the 3 errors only)."""
    values = fit.to_dict()
    true = {"alpha": truth.robot.to_model().alpha, "c_zeta": truth.robot.to_model().c_zeta,
            "c_psi": truth.robot.to_model().c_psi}  # fmt: skip
    for name, relative in TOLERANCE.items():
        found, error = values["params"][name], values["stderr"][name]
        checked = tolerances and (damping or name == "alpha")
        assert not checked or abs(found - true[name]) < relative * true[name], f"{name}: {found:.4g} vs {true[name]}"
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


# Robots whose runs fall (default noise: 0.5 deg and 0.003 per jump, 0.5 deg of pitch drift): issue
# 24's finding, the robot above, a soft and a stiff one; each fitted from the first two seeds whose
# four climbs include one that fell.
FALLING = {
    "finding": Truth.of(alpha=84.0, c_zeta=0.6, c_psi=0.2, psi0_offset_deg=(-1.0, 0.5), zeta0_offset=(-0.006, 0.002)),
    "soft": Truth.of(alpha=62.0, c_zeta=0.9, c_psi=0.45, psi0_offset_deg=(0.8, 1.2), zeta0_offset=(0.005, 0.003)),
    "stiff": Truth.of(alpha=100.0, c_zeta=0.45, c_psi=0.35, psi0_offset_deg=(-0.4, -1.1), zeta0_offset=(-0.002, 0.0)),
}
FALLING_JUMPS = 60


def with_fall(truth: Truth, nth: int) -> list[TouchdownSeries]:
    """The climbs of the ``nth`` seed (from 0) whose four climbs include one that fell."""
    seed, found = -1, 0
    while found <= nth:
        seed += 1
        series = climbs(truth, NoiseModel(), jumps=FALLING_JUMPS, seed=seed)
        found += any(run.fell for run in series)
    return series


@pytest.mark.parametrize("nth", [0, 1])
@pytest.mark.parametrize("name", sorted(FALLING))
def test_recovers_the_truth_with_a_run_that_fell(name, nth):
    series = with_fall(FALLING[name], nth)
    fit = calibrate(series, PAPER.to_model())
    assert_recovered(fit, FALLING[name], damping=False)
    fallen = [i for i, run in enumerate(series) if run.fell]
    assert [position for position, _ in fit.cut_at_fall] == fallen
    assert fit.touchdowns_used == sum(run.pairs for run in series) - len(fallen)
    assert fit.noise["zeta0"] == pytest.approx(0.003, rel=0.25), "the robot's control noise, estimated"


def wild_touchdown(run: TouchdownSeries) -> TouchdownSeries:
    """``run`` with a touchdown after its last, as the detector found one while a virtual robot fell
    (measured: the body crossing the leg's line on its way down, 0.45 m under the last foot)."""
    flipped = not run.right_leg[-1]
    return TouchdownSeries.of(
        state=np.vstack([run.state, [-0.28, -2.34]]),
        foot_height=np.append(run.foot_height, run.foot_height[-1] - 1.2),
        commanded=np.vstack([run.commanded, run.commanded[-2]]),
        right_leg=np.append(run.right_leg, flipped),
        pitch=np.append(run.pitch, run.pitch[-1]),
        fell=run.fell,
    )


def test_a_run_that_fell_is_cut_before_its_fall_and_a_wild_touchdown_is_an_outlier():
    clean = [replace(run, fell=False) for run in climbs(TRUTH, NoiseModel(pitch_drift_deg=0.2), jumps=40)]
    wild = [*clean[:2], wild_touchdown(clean[2]), clean[3]]
    last = len(wild[2].state) - 1
    # Told it fell, the fit leaves out the pair into the fall: the same fit as without that touchdown.
    fell = [*wild[:2], replace(wild[2], fell=True), wild[3]]
    assert len(Pairs.of(fell, steady=True)) == len(Pairs.of(fell)) - 1
    cut, plain = calibrate(fell, PAPER.to_model()), calibrate(clean, PAPER.to_model())
    assert cut.cut_at_fall == ((2, last),) and cut.touchdowns_used == plain.touchdowns_used
    assert cut.to_dict()["params"] == plain.to_dict()["params"]
    assert cut.to_dict()["cut_at_fall"] == [{"series": 2, "touchdown": last}]
    # Not told, the robust fit reports it by run and touchdown, and neither the parameters nor the
    # noise follow it: the noise comes from the pairs it explains.
    fit = calibrate(wild, PAPER.to_model())
    [outlier] = [o for o in fit.outliers if (o.series, o.touchdown) == (2, last)]
    assert outlier.residual > 10 * OUTLIER_SIGMAS
    assert {(o.series, o.touchdown) for o in fit.outliers} == {(o.series, o.touchdown) for o in plain.outliers} | {
        (2, last)
    }
    assert {"series": 2, "touchdown": last, "residual": outlier.residual} in fit.to_dict()["outliers"]
    assert fit.noise_pairs == plain.noise_pairs
    for name, value in fit.to_dict()["params"].items():
        assert np.allclose(
            value, plain.to_dict()["params"][name], rtol=0, atol=0.1 * np.max(plain.to_dict()["stderr"][name])
        ), name
    for name in PARAMETERS:
        assert abs(fit.stderr[name] - plain.stderr[name]) < 0.1 * plain.stderr[name], name
    for name, sigma in plain.noise.items():
        assert fit.noise[name] == pytest.approx(sigma, rel=0.05), name
    assert fit.noise["psi0_deg"] == pytest.approx(0.5, rel=0.3)
