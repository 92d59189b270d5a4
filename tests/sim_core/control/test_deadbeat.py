"""The deadbeat law and the placement law between walls (sim_core/control/deadbeat.py): the horizon
predicts what the map does, the guard never sends a command the design model predicts fails, and
without noise each climbs to and holds targets it was not tuned on."""

import math
from dataclasses import replace

import numpy as np
import pytest

from sim_core.basins.sweep import find_in_place_zeta0
from sim_core.control.controllers import control_step, new_memory
from sim_core.control.deadbeat import ANGLE_STEP, PARAMETER_COUNT, deadbeat_leg, design_deadbeat, horizon_cost
from sim_core.control.height_controller import HeightController
from sim_core.control.laws import DEADBEAT, PLACEMENT, Deadbeat, Pid, Placement
from sim_core.control.study import controlled_loop
from sim_core.model.failures import OK
from sim_core.model.integrate import STATE_SIZE
from sim_core.model.noise import NoiseModel
from sim_core.model.presets import get_preset
from sim_core.model.stride import flight, jump, lift_off
from sim_core.model.validation import ParameterError
from sim_core.viability.guard import lands_in_kernel

MODEL = get_preset("paper").to_model()
PSI0 = math.radians(35.0)
NO_RECORD = np.empty((0, STATE_SIZE))
NO_NOISE = NoiseModel(0.0, 0.0, 0.0, 0.0).record()


@pytest.fixture(scope="module")
def hover():
    return find_in_place_zeta0(MODEL, PSI0)


@pytest.fixture(scope="module")
def law(hover):
    return design_deadbeat(MODEL, 2.4, 35.0, hover)


def test_its_parameters_are_laid_out_as_the_kernel_reads_them(law):
    kind, parameters = law.kernel_args()
    assert kind == DEADBEAT and law.name == "deadbeat"
    assert law.guard and parameters.shape == (PARAMETER_COUNT + len(law.guard),)
    unguarded = design_deadbeat(MODEL, 2.4, 35.0, law.zeta0, viability_guard=False)
    assert unguarded.kernel_args()[1].shape == (PARAMETER_COUNT,)


def test_no_command_leaves_the_viability_kernel_and_a_kernel_that_holds_nothing_sends_the_gaits(law):
    unguarded = replace(law, guard=())
    _, parameters = law.kernel_args()
    _, free = unguarded.kernel_args()
    rng = np.random.default_rng(5)
    refused = 0
    for _ in range(200):
        xdot, ydot = rng.uniform(-1.6, -0.3), rng.uniform(-1.0, 1.0)
        zeta0, height = rng.uniform(0.8, 0.98), rng.uniform(0.0, 4.0)
        _, psi, vx, vy, _, _ = lift_off(xdot, ydot, PSI0, zeta0, MODEL.record(), NO_RECORD)
        _, command, guarded = deadbeat_leg(parameters, PSI0, zeta0, height, xdot, ydot)
        if command == law.zeta0 and guarded:
            continue  # nothing was safe: the gait's own controls
        # The command's jump, cut at its lift-off, reaches the middle inside the kernel.
        status, x1, y1, *_ = flight(psi, vx, vy, MODEL.d_hat, PSI0, command)
        _, psi_1, vx_1, vy_1, _, _ = lift_off(x1, y1, PSI0, command, MODEL.record(), NO_RECORD)
        assert status == OK and lands_in_kernel(parameters, PARAMETER_COUNT, psi_1, vx_1, vy_1, MODEL.d_hat)
        refused += deadbeat_leg(free, PSI0, zeta0, height, xdot, ydot)[1] != command
    assert refused > 0, "somewhere the unguarded law's choice leaves the kernel"
    empty = list(law.guard)
    empty[2 + int(empty[0]) + int(empty[1]) :] = [0.0] * int(empty[0] * empty[1])
    _, nothing = replace(law, guard=tuple(empty)).kernel_args()
    (xdot, ydot), zeta0 = law.state, law.zeta0
    assert deadbeat_leg(nothing, PSI0, zeta0, 1.0, xdot, ydot) == (PSI0, law.zeta0, True)


def test_the_horizon_is_the_maps_own_two_jumps(law, hover):
    """With zero aims and no state weight, the cost is the squared heights the map itself gives for
    touchdowns k + 1 and k + 2 (above this one)."""
    _, parameters = law.kernel_args()
    parameters[16] = 0.0  # q_state off
    (xdot, ydot), zeta0 = law.state, hover - 0.02
    _, psi, vx, vy, _, _ = lift_off(xdot, ydot, PSI0, zeta0, MODEL.record(), NO_RECORD)
    for next_zeta0 in (0.86, 0.9, 0.94):
        status, x1, y1, rise_1, *_ = jump(xdot, ydot, PSI0, zeta0, PSI0, next_zeta0, MODEL.record(), NO_RECORD)
        status_2, _, _, rise_2, *_ = jump(x1, y1, PSI0, next_zeta0, PSI0, hover, MODEL.record(), NO_RECORD)
        assert status == status_2 == OK
        body = zeta0 * math.sin(PSI0)
        first = rise_1 + next_zeta0 * math.sin(PSI0) - body
        second = rise_1 + rise_2 + hover * math.sin(PSI0) - body
        cost = horizon_cost(parameters, psi, vx, vy, body, PSI0, next_zeta0, 0.0, 0.0, NO_RECORD)
        assert cost == pytest.approx(first**2 + second**2, rel=1e-9)


def test_the_guard_never_sends_a_command_the_model_predicts_fails(law, hover):
    """Over section states far and near the gait, every command but the fallback (the gait's own
    zeta0, flagged) is one whose jump the model predicts goes, and the gait's controls after it."""
    _, parameters = law.kernel_args()
    rng = np.random.default_rng(27)
    sent = 0
    for _ in range(300):
        xdot, ydot = rng.uniform(-1.6, -0.3), rng.uniform(-1.0, 1.0)
        zeta0, height = rng.uniform(0.8, 0.98), rng.uniform(0.0, 4.0)
        if lift_off(xdot, ydot, PSI0, zeta0, MODEL.record(), NO_RECORD)[0] != OK:
            continue
        angle, command, guarded = deadbeat_leg(parameters, PSI0, zeta0, height, xdot, ydot)
        assert angle == PSI0 and 0.8 <= command <= 0.98
        status, x1, y1, *_ = jump(xdot, ydot, PSI0, zeta0, PSI0, command, MODEL.record(), NO_RECORD)
        if guarded and command == law.zeta0:
            continue  # nothing went, or nothing stayed in the viability kernel: the gait's own zeta0
        assert status == OK, (xdot, ydot, zeta0, command)
        sent += 1
        follow = jump(x1, y1, PSI0, command, PSI0, hover, MODEL.record(), NO_RECORD)[0]
        assert follow == OK, (xdot, ydot, zeta0, command)
    assert sent > 100


@pytest.mark.parametrize(("target", "psi0_deg"), [(1.6, 35.0), (2.9, 35.0), (2.2, 32.0)])
def test_without_noise_it_climbs_to_the_target_and_holds_it(target, psi0_deg):
    """Targets and a leg angle it was not tuned on: it is within 10% of the climb no later than
    today's PID on the same climb, and then stays within 1 mm of l0 of the target."""
    psi0 = math.radians(psi0_deg)
    hover = find_in_place_zeta0(MODEL, psi0)
    law = design_deadbeat(MODEL, target, psi0_deg, hover)
    deadbeat = _climb(law, law.state, psi0, hover)
    pid = _climb(Pid(HeightController(target, hover), psi0_deg), law.state, psi0, hover)
    risen = [np.flatnonzero(np.abs(heights - target) < 0.1 * (target - heights[0]))[0] for heights in (deadbeat, pid)]
    assert risen[0] <= risen[1], risen
    np.testing.assert_allclose(deadbeat[-20:], target, atol=1e-3)


def _climb(law, start, psi0, zeta0, jumps=60):
    kind, parameters = law.kernel_args()
    heights = np.full(jumps + 1, math.nan)
    clipped = np.zeros(jumps, dtype=np.bool_)
    status, done = controlled_loop(start[0], start[1], psi0, zeta0, kind, parameters, 0, NO_NOISE,
                                   MODEL.record(), heights, clipped)  # fmt: skip
    assert (status, done) == (OK, jumps)
    return heights


def test_the_pitch_is_fed_to_the_leg_angle_as_for_pid_pitch(law):
    kind, parameters = law.kernel_args()
    pitch = math.radians(2.0)
    left = control_step(kind, parameters, new_memory(kind, PSI0, 0.9), 1.0, pitch, -0.9, -0.25, True)
    right = control_step(kind, parameters, new_memory(kind, PSI0, 0.9), 1.0, pitch, -0.9, -0.25, False)
    assert left[0] == pytest.approx(PSI0 - pitch) and right[0] == pytest.approx(PSI0 + pitch)
    assert left[1] == right[1], "zeta0 does not depend on the wall"


@pytest.mark.parametrize(
    ("change", "field"),
    [({"climb_per_jump": 0.0}, "climb_per_jump"), ({"q_state": -1.0}, "q_state"), ({"zeta0": 0.99}, "zeta0"),
     ({"psi0_deg": 70.0}, "psi0_deg"), ({"model": (1.0, 2.0)}, "model"), ({"state": (math.nan, 0.0)}, "state"),
     ({"zeta0_range": (0.9, 0.85)}, "zeta0_range")],
)  # fmt: skip
def test_its_parameters_are_checked_naming_the_field(law, change, field):
    values = {name: getattr(law, name) for name in Deadbeat.__dataclass_fields__} | change
    with pytest.raises(ParameterError) as caught:
        Deadbeat(**values)
    assert caught.value.field == field


@pytest.fixture(scope="module")
def placement(hover):
    return design_deadbeat(MODEL, 2.4, 35.0, hover, law=Placement)


def test_the_placement_law_is_its_own_branch_and_without_an_angle_step_it_is_the_deadbeat(law, placement):
    kind, parameters = placement.kernel_args()
    assert kind == PLACEMENT != DEADBEAT and placement.name == "placement"
    assert parameters[ANGLE_STEP] == pytest.approx(math.radians(3.0)) and law.kernel_args()[1][ANGLE_STEP] == 0.0
    held = replace(placement, angle_step_deg=0.0, q_state=law.q_state)
    rng = np.random.default_rng(11)
    for _ in range(40):
        xdot, ydot = rng.uniform(-1.4, -0.5), rng.uniform(-0.8, 0.6)
        zeta0, height, pitch = rng.uniform(0.82, 0.96), rng.uniform(0.5, 4.0), rng.normal(0.0, 0.02)
        commands = [
            control_step(*each.kernel_args(), new_memory(DEADBEAT, PSI0, zeta0), height, pitch, xdot, ydot, True)
            for each in (law, held)
        ]
        assert commands[0] == commands[1]


def test_the_placement_law_sends_only_legs_the_model_predicts_go(placement, hover):
    """Over section states far and near the gait: the angle is the gait's or a step either side,
    and every leg but the fallback (the gait's own, flagged) is one whose jump the model predicts
    goes, and the gait's controls after it; some states take a turned angle."""
    _, parameters = placement.kernel_args()
    step = math.radians(placement.angle_step_deg)
    rng = np.random.default_rng(43)
    sent, turned = 0, 0
    for _ in range(200):
        xdot, ydot = rng.uniform(-1.6, -0.3), rng.uniform(-1.0, 1.0)
        zeta0, height = rng.uniform(0.8, 0.98), rng.uniform(0.0, 4.0)
        if lift_off(xdot, ydot, PSI0, zeta0, MODEL.record(), NO_RECORD)[0] != OK:
            continue
        angle, command, guarded = deadbeat_leg(parameters, PSI0, zeta0, height, xdot, ydot)
        assert min(abs(angle - PSI0 - offset) for offset in (0.0, -step, step)) < 1e-12
        assert 0.8 <= command <= 0.98
        if guarded and (angle, command) == (PSI0, placement.zeta0):
            continue
        status, x1, y1, *_ = jump(xdot, ydot, PSI0, zeta0, angle, command, MODEL.record(), NO_RECORD)
        assert status == OK, (xdot, ydot, zeta0, angle, command)
        assert jump(x1, y1, angle, command, PSI0, hover, MODEL.record(), NO_RECORD)[0] == OK
        sent += 1
        turned += angle != PSI0
    assert sent > 60 and turned > 0


@pytest.mark.parametrize(("target", "psi0_deg"), [(1.6, 35.0), (2.9, 32.0)])
def test_without_noise_the_placement_law_climbs_to_the_target_and_holds_it(target, psi0_deg):
    psi0 = math.radians(psi0_deg)
    hover = find_in_place_zeta0(MODEL, psi0)
    law = design_deadbeat(MODEL, target, psi0_deg, hover, law=Placement)
    np.testing.assert_allclose(_climb(law, law.state, psi0, hover)[-20:], target, atol=1e-3)


def test_the_placement_laws_angle_step_is_checked_naming_the_field(placement):
    values = {name: getattr(placement, name) for name in Placement.__dataclass_fields__} | {"angle_step_deg": 20.0}
    with pytest.raises(ParameterError) as caught:
        Placement(**values)
    assert caught.value.field == "angle_step_deg"


def test_the_placement_laws_angle_stays_within_the_servos_range_without_a_pitch(hover):
    """With the gait's angle 1° inside the range, the step below it is never sent, tracked pitch or not."""
    law = design_deadbeat(MODEL, 2.4, 35.0, hover, law=Placement, psi0_range_deg=(34.0, 60.0))
    kind, parameters = law.kernel_args()
    rng = np.random.default_rng(8)
    angles = set()
    for _ in range(60):
        xdot, ydot = rng.uniform(-1.4, -0.5), rng.uniform(-0.8, 0.6)
        zeta0, height = rng.uniform(0.82, 0.96), rng.uniform(0.5, 4.0)
        psi0, _, _ = control_step(kind, parameters, new_memory(kind, PSI0, zeta0), height, math.nan, xdot, ydot, True)
        assert math.radians(34.0) <= psi0 <= math.radians(60.0)
        angles.add(round(math.degrees(psi0), 9))
    assert angles <= {35.0, 38.0} and 38.0 in angles
