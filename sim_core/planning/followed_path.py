"""The body's path of a plan followed under noise (:func:`sim_core.planning.follow.follow_plan`'s
trial of a seed), sampled for the 3D view.

The trial is stepped one touchdown at a time by :class:`sim_core.planning.attempts.Attempts` (the
same compiled loop, the same draws, the same replans: its touchdowns are ``follow_plan``'s), and
each touchdown's state is kept: the body as it arrived (its velocity as disturbed), the side and
segment the foot is on, the leg as realised. Each jump is then sampled by
:func:`sim_core.world.trajectory.jump_path` from that touchdown with that leg in stance and the next
touchdown's realised leg flying: it lands where the trial's next touchdown is (tested to 1e-12).
Beside the path: the foothold each touchdown was aimed at (the plan's, or a replan's, row for it)
and whether the foot landed on it.

A trial that fails ends in a jump whose flying leg was drawn but never kept by the loop: that jump
is sampled with the stance leg flying again (its stance is exact; its flight is a sketch of how it
failed).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from sim_core.model.controls import LegControl
from sim_core.model.failures import OK
from sim_core.model.integrate import STATE_SIZE
from sim_core.model.noise import NoiseModel
from sim_core.model.params import ModelParams
from sim_core.model.trajectory import DEFAULT_SAMPLE_RATE, MAX_STANCE_NODES, joined_columns
from sim_core.planning.attempts import Attempts
from sim_core.planning.follow import PSI0, SEGMENT, SIDE, YDOT, ZETA0, X
from sim_core.planning.planner import Plan
from sim_core.world.trajectory import jump_path
from sim_core.world.world import World


@dataclass(frozen=True)
class FollowedPath:
    """A followed plan's trial, sampled.

    Attributes:
        columns: :attr:`sim_core.model.trajectory.Trajectory.COLUMNS` (nondimensional, wall
            coordinates of the world: ``y`` from the world's floor, the foot where the world puts it).
        touchdown_times: shape (n,), each touchdown's time [sqrt(l0/g)].
        landings: shape (m, 2), where each sampled jump's flight put the body down (``x, y``
            [l0]): touchdowns 1 .. m's, the trial's own (the test of this module).
        touchdowns: shape (n, 4), the body at each touchdown: ``x, y, xdot, ydot`` (the velocity as
            disturbed after the jump that brought it there).
        sides, segments: shape (n,), where each touchdown's foot is (0 left, 1 right).
        legs: shape (n, 2), each touchdown's leg as realised: ``psi0`` [rad], ``zeta0`` [l0].
        aims: shape (n, 3), the foothold each touchdown was aimed at: segment, target ``x, y``
            [l0] (NaN where none was: the plan ended below the goal and was not replanned).
        hits: shape (n,), the foot landed on the segment aimed at (False where none was aimed at).
        reached, failed: the trial reached the goal; it ended in a failure (else: at the cap).
        replans: the replans made.
    """

    columns: dict[str, np.ndarray]
    touchdown_times: np.ndarray
    landings: np.ndarray
    touchdowns: np.ndarray
    sides: np.ndarray
    segments: np.ndarray
    legs: np.ndarray
    aims: np.ndarray
    hits: np.ndarray
    reached: bool
    failed: bool
    replans: int

    @property
    def jumps(self) -> int:
        """The jumps completed (to the last touchdown), as :class:`sim_core.planning.follow.FollowOutcome`'s."""
        return len(self.touchdowns) - 1


def followed_path(
    model: ModelParams,
    world: World,
    plan: Plan,
    goal: float,
    noise: NoiseModel,
    seed: int,
    *,
    cap: int = 200,
    sample_rate: float = DEFAULT_SAMPLE_RATE,
) -> FollowedPath:
    """``follow_plan(model, world, plan, goal, noise, seed, cap=cap)``'s trial with its path sampled
    at ``sample_rate`` per sqrt(l0/g) (the law's default settings and replans)."""
    attempts = Attempts(model, world, plan, goal, noise, cap=cap)
    attempt = attempts.start(seed)
    trials = np.array([state[0] for state in attempt.states])
    legs = trials[:, [PSI0, ZETA0]]
    aims, previous = [], None
    for _trial, plan_aims, row, _replans in attempt.states:
        fresh = previous is None or plan_aims is not previous[0] or row == previous[1] + 1
        aims.append(plan_aims[row, :3] if fresh else np.full(3, math.nan))
        previous = (plan_aims, row)
    aims = np.array(aims)
    hits = aims[:, 0] == trials[:, SEGMENT]
    record = np.empty((MAX_STANCE_NODES, STATE_SIZE))
    pieces, times, landings, clock = [], [0.0], [], 0.0
    parameters = attempts.record
    ends = len(trials) - (0 if attempt.failed else 1)  # a failed trial's last jump is sampled too
    for k in range(ends):
        trial = trials[k]
        flying = legs[k + 1] if k + 1 < len(trials) else legs[k]
        pieces_k, status, landing, _side, _segment, duration = jump_path(
            parameters, attempts.sides, trial[X : YDOT + 1], int(trial[SIDE]), int(trial[SEGMENT]),
            LegControl(*legs[k]), LegControl(*flying), clock, sample_rate, k, record,
        )  # fmt: skip
        pieces.extend(pieces_k)
        if status != OK or k + 1 >= len(trials):
            break
        clock += duration
        times.append(clock)
        landings.append(landing[:2])
    return FollowedPath(
        columns=joined_columns(pieces),
        touchdown_times=np.array(times),
        landings=np.array(landings).reshape(-1, 2),
        touchdowns=trials[:, X : YDOT + 1].copy(),
        sides=trials[:, SIDE].astype(int),
        segments=trials[:, SEGMENT].astype(int),
        legs=legs,
        aims=aims,
        hits=hits,
        reached=not attempt.failed and _at_goal(trials[-1], goal),
        failed=attempt.failed,
        replans=attempt.states[-1][3],
    )


def _at_goal(trial: np.ndarray, goal: float) -> bool:
    return bool(trial[X + 1] - trial[ZETA0] * math.sin(trial[PSI0]) >= goal)
