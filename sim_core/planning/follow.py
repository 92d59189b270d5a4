"""A plan followed under noise: the foot-placement law aiming each touchdown at the plan's
foothold, replanning from where the robot is when it is off its plan (docs/worlds.md,
"Following a plan").

A trial starts as MJTF's world trials do (:mod:`sim_core.robustness.world_trials`): touchdown 0
on the left side at the plan's first foot, numba's generator seeded by the trial's seed, the noise
drawn in the same order (at each lift-off a pitch step and the next leg's controls, after each
jump the velocity) — so the same seed gives the same draws to a fixed schedule and to this law.
At each lift-off the law (:func:`sim_core.control.placement.place_from_liftoff`) sees the body
leave the wall (tracked) and sets the coming leg for the plan's next foothold; the leg is sent
turned back by the tracked pitch and clipped to the leg's range, then drawn with its noise.

Off plan — the law finds no leg that lands on the plan's next foothold with its margins and goes
on, or the plan ends below the goal — the compiled loop stops *before* that lift-off's draws,
the planner (:func:`sim_core.planning.planner.replan`) plans again from that lift-off, and the
loop goes on with the draws where they were. A trial ends at the goal (a foot at or above it),
at a failure (the floor included), or at ``cap`` jumps.

Every draw is also tallied in the trial (from :data:`TALLY`: by kind, the standard normals drawn,
counted and their squares summed, :func:`sim_core.model.noise_rules.tallied_draw`): a trial drawn
from an importance sampling's proposal is weighed by them (:mod:`sim_core.planning.plan_importance`);
the draws themselves are the same.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from sim_core._jit import kernel
from sim_core.control.laws.placement import PlacementSettings
from sim_core.control.placement import (
    AIM_SIZE,
    OFF_PLAN,
    PLACED,
    PSI0_HIGH,
    PSI0_LOW,
    landing_margin,
    place_from_liftoff,
)
from sim_core.model.failures import FLOOR, FLOOR_HEIGHT, OK
from sim_core.model.integrate import PSI, PSI_DOT, STATE_SIZE, ZETA_DOT
from sim_core.model.noise import NoiseModel
from sim_core.model.noise_rules import TALLY_SIZE, seed_trial, tallied_commanded_controls, tallied_pitch_step
from sim_core.model.params import ModelParams
from sim_core.model.stride import liftoff_velocity
from sim_core.planning.planner import Plan, replan
from sim_core.robustness.world_trials import tallied_disturbed_on_side
from sim_core.world.geometry import SideArrays, pack
from sim_core.world.stride import foothold_stance, world_flight
from sim_core.world.world import World

# A trial's state at a touchdown (one float array, in and out of the compiled loop): the body, its
# side and segment, the leg as realised (the physics') and as sent (the law's), the pitch, the jump,
# and the lift-off that follows once the stance has run; then the trial's draws so far by kind,
# counted and their squares summed in units of their standard deviations (the tally an
# importance-sampled trial is weighed by, sim_core.planning.plan_importance; a plain trial's is unread)
X, Y, XDOT, YDOT, SIDE, SEGMENT, PSI0, ZETA0, SENT_PSI0, SENT_ZETA0, PITCH, JUMP = range(12)
LIFT_X, LIFT_Y, LIFT_XDOT, LIFT_YDOT = range(12, 16)  # the lift-off under way, tracked (wall coordinates)
TALLY = 16  # noise_rules' tally: TALLY_SIZE slots
TRIAL_SIZE = TALLY + TALLY_SIZE
REACHED, CAPPED, REPLAN = -1, -2, -3  # how the loop stops, beside a failure's code
MAX_REPLANS = 3  # a trial's replans at most; then the law's best leg goes out, on plan or not


def plan_aims(plan: Plan) -> np.ndarray:
    """The law's aims (:mod:`sim_core.control.placement`'s layout), row ``k`` for touchdown ``k``
    (row 0 unused): each touchdown's segment, foot, velocity and leg, and the next one's (NaN after
    the last)."""
    steps = plan.steps
    aims = np.full((len(steps), AIM_SIZE), math.nan)
    for k, step in enumerate(steps):
        aims[k, :7] = (step.segment, *step.target, *step.velocity, step.leg.psi0, step.leg.zeta0)
        if k + 1 < len(steps):
            after = steps[k + 1]
            aims[k, 7:] = (after.leg.psi0, after.leg.zeta0, after.target[1], *after.velocity, after.segment)
    return aims


@kernel
def start_trial(trial, aims, foot_x, foot_y, segment, xdot, ydot, seed, noise):
    """Seed the generator and fill ``trial`` with touchdown 0: the foot at ``(foot_x, foot_y)`` on the
    left side's ``segment``, the plan's first leg sent and realised with fresh draws (tallied from
    none)."""
    seed_trial(seed)
    trial[TALLY:] = 0.0
    sent_psi0, sent_zeta0 = aims[0, 5], aims[0, 6]
    psi0, zeta0 = tallied_commanded_controls(0, 0.0, sent_psi0, sent_zeta0, noise, trial[TALLY:])
    trial[X], trial[Y] = foot_x + zeta0 * math.cos(psi0), foot_y + zeta0 * math.sin(psi0)
    trial[XDOT], trial[YDOT], trial[SIDE], trial[SEGMENT] = xdot, ydot, 0.0, segment
    trial[PSI0], trial[ZETA0], trial[SENT_PSI0], trial[SENT_ZETA0] = psi0, zeta0, sent_psi0, sent_zeta0
    trial[PITCH], trial[JUMP] = 0.0, 0.0


@kernel
def expected_leg(trial):
    """The leg of this touchdown as the robot expects it realised: as sent, turned by the pitch."""
    turn = trial[PITCH] if trial[SIDE] == 0.0 else -trial[PITCH]
    return trial[SENT_PSI0] + turn, trial[SENT_ZETA0]


@kernel
def follow(trial, aims, row, goal, cap, may_replan, noise, model, sides, settings):
    """Advance ``trial`` from its touchdown, which is the plan's ``row``, until the goal
    (:data:`REACHED`), a failure (its code), ``cap`` jumps in all (:data:`CAPPED`) or, where
    ``may_replan``, the robot off its plan at a lift-off (:data:`REPLAN`, before that lift-off's
    draws; the lift-off in ``trial``). Returns ``(outcome, row)``, the plan's row of the touchdown
    ``trial`` holds. Its draws are tallied in ``trial`` (from :data:`TALLY`)."""
    no_record = np.empty((0, STATE_SIZE))
    tally = trial[TALLY:]  # a view: the tally goes on in the trial
    final = np.empty(STATE_SIZE)
    while True:
        if trial[Y] - trial[ZETA0] * math.sin(trial[PSI0]) >= goal:
            return REACHED, row
        if trial[JUMP] >= cap:
            return CAPPED, row
        side = int(trial[SIDE])
        status = lift_off_from(trial, model, sides, final, no_record)
        if status != OK:
            return status, row
        if row + 1 >= aims.shape[0]:  # the plan ends below the goal
            if may_replan:
                return REPLAN, row
            found, psi0, zeta0 = OFF_PLAN, aims[row, 5], aims[row, 6]
        else:
            liftoff = trial[LIFT_X], trial[LIFT_Y], trial[LIFT_XDOT], trial[LIFT_YDOT]
            found, psi0, zeta0 = place_from_liftoff(model, sides, side, *liftoff, aims[row + 1], settings)
            if found != PLACED and may_replan:
                return REPLAN, row
        next_on_left = side == 1
        turned = psi0 - (trial[PITCH] if next_on_left else -trial[PITCH])
        sent_psi0 = min(max(turned, settings[PSI0_LOW]), settings[PSI0_HIGH])
        k = int(trial[JUMP])
        next_pitch = tallied_pitch_step(trial[PITCH], noise, tally)
        next_psi0, next_zeta0 = tallied_commanded_controls(k + 1, next_pitch, sent_psi0, zeta0, noise, tally)
        status, x, y, xdot, ydot, segment, _ = world_flight(
            trial[LIFT_X], trial[LIFT_Y], trial[LIFT_XDOT], trial[LIFT_YDOT], side, next_psi0, next_zeta0, sides
        )
        if status != OK:
            return status, row
        if y < FLOOR_HEIGHT:
            return FLOOR, row
        side = 1 - side
        xdot, ydot = tallied_disturbed_on_side(side, xdot, ydot, noise, tally)  # as MJTF's world trials
        trial[X], trial[Y], trial[XDOT], trial[YDOT] = x, y, xdot, ydot
        trial[SIDE], trial[SEGMENT], trial[PSI0], trial[ZETA0] = side, segment, next_psi0, next_zeta0
        trial[SENT_PSI0], trial[SENT_ZETA0], trial[PITCH], trial[JUMP] = sent_psi0, zeta0, next_pitch, k + 1
        row = min(row + 1, aims.shape[0] - 1)


@kernel
def lift_off_from(trial, model, sides, final, no_record):
    """Run the stance of ``trial``'s touchdown and put its lift-off (wall coordinates) in ``trial``;
    returns the stance's status (``final``: scratch for its last state)."""
    side, segment = int(trial[SIDE]), int(trial[SEGMENT])
    mirror = 1.0 if side == 0 else -1.0
    status, _ = foothold_stance(mirror * trial[XDOT], trial[YDOT], trial[PSI0], trial[ZETA0], model, sides, side,
                                segment, final, no_record)  # fmt: skip
    if status != OK:
        return status
    vx, vy = liftoff_velocity(final[PSI], final[ZETA_DOT], final[PSI_DOT])
    trial[LIFT_X] = trial[X] - mirror * (trial[ZETA0] * math.cos(trial[PSI0]) - math.cos(final[PSI]))
    trial[LIFT_Y] = trial[Y] - trial[ZETA0] * math.sin(trial[PSI0]) + math.sin(final[PSI])
    trial[LIFT_XDOT], trial[LIFT_YDOT] = mirror * vx, vy
    return OK


@kernel
def planned_margin(trial, aims, row, model, sides, settings):
    """The margin (:func:`sim_core.control.placement.landing_margin`) of the landing the law aims at
    from ``trial``'s touchdown (the plan's ``row``), on the model without noise: the stance, the law's
    leg at its lift-off, that leg's flight. -inf where the stance or the flight fails or the body
    comes down below the floor; +inf where the plan has no touchdown after this one."""
    if row + 1 >= aims.shape[0]:
        return math.inf
    work = trial.copy()
    if lift_off_from(work, model, sides, np.empty(STATE_SIZE), np.empty((0, STATE_SIZE))) != OK:
        return -math.inf
    side = int(work[SIDE])
    liftoff = work[LIFT_X], work[LIFT_Y], work[LIFT_XDOT], work[LIFT_YDOT]
    _, psi0, zeta0 = place_from_liftoff(model, sides, side, *liftoff, aims[row + 1], settings)
    status, _, body_y, _, _, segment, _ = world_flight(*liftoff, side, psi0, zeta0, sides)
    if status != OK or body_y < FLOOR_HEIGHT:
        return -math.inf
    return landing_margin(sides, 1 - side, segment, body_y - zeta0 * math.sin(psi0), psi0, settings)


@dataclass(frozen=True)
class FollowOutcome:
    """One trial: ``reached`` the goal, else ``status`` (a failure's code, or 0 at the cap); the
    jumps done, the replans made and the planner's seconds on them."""

    reached: bool
    status: int
    jumps: int
    replans: int
    replan_seconds: float


def follow_plan(
    model: ModelParams,
    world: World,
    plan: Plan,
    goal: float,
    noise: NoiseModel,
    seed: int,
    *,
    cap: int = 200,
    settings: PlacementSettings | None = None,
    sides: SideArrays | None = None,
    max_replans: int = MAX_REPLANS,
) -> FollowOutcome:
    """One noisy trial of ``plan`` (from its touchdown 0 to a foot at ``goal`` [l0]) in ``world``,
    the law's ``settings`` (defaults :class:`PlacementSettings`), replanning at most ``max_replans``
    times."""
    sides = pack(world, model.mu) if sides is None else sides
    settings_array = (settings or PlacementSettings()).array()
    record, noise_record = model.record(), noise.record()
    first = plan.steps[0]
    foot_x, foot_y = first.target
    trial = np.empty(TRIAL_SIZE)
    aims = plan_aims(plan)
    start_trial(trial, aims, foot_x, foot_y, first.segment, *first.velocity, seed, noise_record)
    row, replans, seconds = 0, 0, 0.0
    while True:
        outcome, row = follow(trial, aims, row, goal, cap, replans < max_replans, noise_record, record, sides,
                              settings_array)  # fmt: skip
        if outcome != REPLAN:
            break
        replans += 1
        started = time.perf_counter()
        fresh = replanned(model, world, goal, trial, noise, seed)
        seconds += time.perf_counter() - started
        if fresh is not None:
            aims, row = fresh, 0
        else:  # no way on from here: the law aims at what it had, without replanning again
            replans = max_replans
    jumps = int(trial[JUMP])
    if outcome == REACHED:
        return FollowOutcome(True, OK, jumps, replans, seconds)
    return FollowOutcome(False, OK if outcome == CAPPED else int(outcome), jumps, replans, seconds)


def replanned(model: ModelParams, world: World, goal: float, trial: np.ndarray, noise: NoiseModel, seed: int):
    """The aims of a plan from the lift-off ``trial`` stopped at (:data:`REPLAN`) to ``goal`` [l0], the
    planner's noisy draws from ``seed``; None where none reaches the goal."""
    touchdown = (trial[X:SIDE].copy(), int(trial[SIDE]), int(trial[SEGMENT]), expected_leg(trial))
    fresh = replan(model, world, goal, touchdown, liftoff=tuple(trial[LIFT_X : LIFT_YDOT + 1]), noise=noise, seed=seed)
    return plan_aims(fresh) if fresh.reaches_goal and len(fresh.steps) > 1 else None


def law_us_per_jump(model: ModelParams, sides: SideArrays, plan: Plan, settings: np.ndarray) -> float:
    """The compiled law's CPU time per call [µs] at the plan's own lift-offs (as a trial calls it):
    the best of three runs of about 50 ms each, by the thread's clock (a busy machine does not
    inflate it)."""
    aims, calls, record = plan_aims(plan), [], model.record()
    final, no_record = np.empty(STATE_SIZE), np.empty((0, STATE_SIZE))
    for k, step in enumerate(plan.steps[:-1]):
        inward = 1.0 if step.side == 0 else -1.0
        status, _ = foothold_stance(inward * step.velocity[0], step.velocity[1], step.leg.psi0, step.leg.zeta0,
                                    record, sides, step.side, step.segment, final, no_record)  # fmt: skip
        if status != OK:
            continue
        vx, vy = liftoff_velocity(final[PSI], final[ZETA_DOT], final[PSI_DOT])
        liftoff = (step.target[0] + inward * math.cos(final[PSI]), step.target[1] + math.sin(final[PSI]),
                   inward * vx, vy)  # fmt: skip
        calls.append((step.side, *liftoff, aims[k + 1]))
    if not calls:
        return 0.0
    best = math.inf
    for _ in range(3):
        started, count = time.thread_time(), 0
        while time.thread_time() - started < 0.05:
            for call in calls:
                place_from_liftoff(record, sides, *call, settings)
                count += 1
        best = min(best, (time.thread_time() - started) / count * 1e6)
    return best
