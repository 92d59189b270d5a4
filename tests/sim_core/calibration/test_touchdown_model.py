"""The model's prediction of detected touchdowns (sim_core.calibration.touchdown_model): one map jump between the
detector's crossings, legs turned by their offsets and the pitch, and its linearisation."""

import math

import numpy as np
import pytest
from numpy.testing import assert_allclose

from sim_core import ControlSchedule, LegControl, find_fixed_point
from sim_core.calibration.touchdown_model import INPUTS, RISE, XDOT, YDOT, predict_pairs, sensitivities
from sim_core.calibration.touchdown_series import PSI0_ERROR, ZETA0_ERROR, Pairs, TouchdownSeries
from sim_core.model.integrate import STATE_SIZE
from sim_core.model.stride import jump

COMMANDED = LegControl.from_degrees(30.0, 0.9)
NO_OFFSETS = np.zeros(2)
SAME_JUMP_TOL = 1e-12  # the kernel against itself, through the detector's shifts and back
DERIVATIVE_STEP = 1e-4  # [sqrt(g l0), rad, l0]
DERIVATIVE_TOL = 1e-5  # two central differences: O(step^2) apart, and the integrator's noise / step


def _pairs(states, commanded, *, pitch=None, right_first=False) -> Pairs:
    n = len(states)
    series = TouchdownSeries.of(
        state=states,
        foot_height=np.zeros(n),
        commanded=[(leg.psi0, leg.zeta0) for leg in commanded],
        right_leg=[(k % 2 == 1) != right_first for k in range(n)],
        pitch=pitch,
    )
    return Pairs.of([series])


def _predict(model, pairs, psi0_offsets=NO_OFFSETS, zeta0_offsets=NO_OFFSETS):
    out = np.empty((len(pairs), 3))
    failed = predict_pairs(pairs.before, pairs.after, model.record(), psi0_offsets, zeta0_offsets, out)
    return out, failed


def test_without_offsets_or_pitch_the_prediction_is_one_map_jump(paper):
    states = [(-0.93, -0.17), (-0.9, -0.2)]
    out, failed = _predict(paper, _pairs(states, [COMMANDED, COMMANDED]))
    leg = (COMMANDED.psi0, COMMANDED.zeta0)
    status, xdot, ydot, rise, *_ = jump(*states[0], *leg, *leg, paper.record(), np.empty((0, STATE_SIZE)))
    assert failed == 0 and status == 0
    assert_allclose(out[0], [xdot, ydot, rise], rtol=0, atol=SAME_JUMP_TOL)


def test_a_measured_gait_maps_to_itself_whatever_the_servos_offset(paper):
    """Both legs offset alike: the robot walks the realised leg's gait, the detector sees each
    touchdown shifted the same way, so the measured touchdown is a fixed point of the prediction
    and the rise is the gait's."""
    offset_deg, offset_zeta = 2.0, -0.02
    realised = LegControl(COMMANDED.psi0 + math.radians(offset_deg), COMMANDED.zeta0 + offset_zeta)
    gait = find_fixed_point(paper, ControlSchedule.of(realised), 1, (-0.93, -0.17))
    xdot, ydot = gait.state
    # The detector meets the commanded leg's line a flight time later (gravity 1).
    shift = (realised.zeta0 * math.cos(realised.psi0) - COMMANDED.zeta0 * math.cos(COMMANDED.psi0)) / abs(xdot)
    measured = (xdot, ydot - shift)
    offsets = np.full(2, math.radians(offset_deg)), np.full(2, offset_zeta)
    out, failed = _predict(paper, _pairs([measured, measured], [COMMANDED, COMMANDED]), *offsets)
    assert failed == 0
    assert_allclose(out[0, [XDOT, YDOT]], measured, rtol=0, atol=1e-9)
    assert out[0, RISE] == pytest.approx(gait.climb_per_period, abs=1e-9)
    naive, _ = _predict(paper, _pairs([measured, measured], [COMMANDED, COMMANDED]))
    assert abs(naive[0, YDOT] - measured[1]) > 1e-3, "without the offsets the model misses"


def test_the_pitch_turns_the_left_leg_up_and_the_right_leg_down(paper):
    """A pitch at a touchdown is the commanded leg turned, for the robot and the detector alike."""
    pitch = (math.radians(1.5), math.radians(-0.5))
    states = [(-0.93, -0.17), (-0.9, -0.2)]
    pitched, _ = _predict(paper, _pairs(states, [COMMANDED, COMMANDED], pitch=pitch))
    turned = [
        LegControl(COMMANDED.psi0 + pitch[0], COMMANDED.zeta0),  # left wall: + pitch
        LegControl(COMMANDED.psi0 - pitch[1], COMMANDED.zeta0),  # right wall: - pitch
    ]
    level, _ = _predict(paper, _pairs(states, turned))
    assert_allclose(pitched, level, rtol=0, atol=SAME_JUMP_TOL)


def test_a_failing_jump_is_nan_and_counted(paper):
    steep = LegControl.from_degrees(70.0, 0.9)  # outside the friction cone: the stance slips
    pairs = _pairs([(-0.93, -0.17), (-0.9, -0.2), (-0.9, -0.2)], [COMMANDED, steep, COMMANDED])
    out, failed = _predict(paper, pairs)
    assert failed == 1
    assert np.all(np.isfinite(out[0])) and np.all(np.isnan(out[1]))


@pytest.mark.parametrize("column", range(len(INPUTS)))
def test_sensitivities_are_the_predictions_derivatives(paper, column):
    """Each column against central differences of its own, at a step ten times or more the module's."""
    pairs = _pairs([(-0.93, -0.17), (-0.9, -0.2), (-0.95, -0.15)], [COMMANDED] * 3)
    slope = sensitivities(pairs, paper.record(), NO_OFFSETS, NO_OFFSETS)
    assert slope.shape == (2, 3, len(INPUTS))
    table, index, _ = INPUTS[column]
    moved = []
    for sign in (1.0, -1.0):
        shifted = Pairs(pairs.before.copy(), pairs.after.copy(), pairs.origin)
        getattr(shifted, table)[:, index] += sign * DERIVATIVE_STEP
        moved.append(_predict(paper, shifted)[0])
    differences = (moved[0] - moved[1]) / (2 * DERIVATIVE_STEP)
    assert_allclose(slope[:, :, column], differences, rtol=0, atol=DERIVATIVE_TOL)


def test_a_control_error_is_an_offset_of_that_leg_for_that_jump(paper):
    """What the leg realised beyond the commanded (the per-jump noise calibration asks about) moves the
    prediction as a servo offset of that leg would: the stance leg's here on the left wall, the next on the right."""
    states = [(-0.93, -0.17), (-0.9, -0.2)]
    pairs = _pairs(states, [COMMANDED, COMMANDED])
    pairs.before[:, PSI0_ERROR] = math.radians(1.0)
    pairs.after[:, ZETA0_ERROR] = -0.01
    with_errors, _ = _predict(paper, pairs)
    as_offsets, _ = _predict(
        paper, _pairs(states, [COMMANDED, COMMANDED]), np.array([math.radians(1.0), 0.0]), np.array([0.0, -0.01])
    )
    assert_allclose(with_errors, as_offsets, rtol=0, atol=SAME_JUMP_TOL)
    plain, _ = _predict(paper, _pairs(states, [COMMANDED, COMMANDED]))
    assert np.all(np.abs(with_errors - plain) > 1e-4), "the errors do move the prediction"
