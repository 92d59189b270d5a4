"""A plan's attempts, one touchdown at a time: what splitting a plan's failures
(:mod:`sim_core.planning.plan_splitting`) branches and Monte-Carlo counts.

An attempt is :func:`sim_core.planning.follow.follow_plan`'s trial of its seed, stepped one jump
at a time so that every touchdown's state can be kept and continued from: the trial's state, the
plan it follows (replanned ones included), its row and the replans it has made. Each touchdown is
scored by its *danger*, minus a landing's margin in units of what the law asks
(:func:`sim_core.control.placement.landing_margin`: the foot from its foothold's ends, the leg
inside the friction cone): the larger of the landing just made (touchdown 0's is the plan's own
start, not scored) and the landing the law aims at next, on the model without noise
(:func:`sim_core.planning.follow.planned_margin`; none after the goal). A score is the largest
danger so far; a failure's level is infinite.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from sim_core.control.laws.placement import PlacementSettings
from sim_core.control.placement import landing_margin
from sim_core.model.noise_rules import seed_trial
from sim_core.planning.follow import (
    CAPPED,
    JUMP,
    MAX_REPLANS,
    PSI0,
    REACHED,
    REPLAN,
    SEGMENT,
    SIDE,
    TRIAL_SIZE,
    ZETA0,
    Y,
    follow,
    plan_aims,
    planned_margin,
    replanned,
    start_trial,
)
from sim_core.world.geometry import pack


@dataclass
class Attempt:
    """One attempt as the splitting holds it: its touchdowns' states (and the plan, row and replans
    each was reached with), each touchdown's score (the largest danger so far), and how it ended."""

    states: list[tuple[np.ndarray, np.ndarray, int, int]] = field(default_factory=list)
    scores: list[float] = field(default_factory=list)
    failed: bool = False

    @property
    def jumps(self) -> int:
        """The jumps it completed (to its last touchdown: a failing jump is not counted, as in
        :class:`sim_core.planning.follow.FollowOutcome`)."""
        return int(self.states[-1][0][JUMP])

    @property
    def level(self) -> float:
        return math.inf if self.failed else self.scores[-1]

    def cut(self, level: float) -> Attempt | None:
        """A copy up to its first touchdown past ``level``; None where it passed the level only by
        failing (the copy is then the whole attempt)."""
        at = next((i for i, score in enumerate(self.scores) if score > level), None)
        return None if at is None else Attempt(self.states[: at + 1], self.scores[: at + 1])


class Attempts:
    """Attempts at one ``plan`` in one ``world`` to a foot at ``goal`` [l0] under ``noise``, the law's
    ``settings`` (None: the defaults), at most ``max_replans`` replans and ``cap`` jumps an attempt:
    started, continued one touchdown at a time, replanned."""

    def __init__(self, model, world, plan, goal, noise, settings=None, *, max_replans=MAX_REPLANS, cap=200):
        self.model, self.world, self.goal, self.noise = model, world, goal, noise
        self.max_replans, self.cap = max_replans, cap
        self.sides, self.record, self.noise_record = pack(world, model.mu), model.record(), noise.record()
        self.settings = (settings or PlacementSettings()).array()
        self.aims = plan_aims(plan)
        self.first = plan.steps[0]

    def start(self, seed: int) -> Attempt:
        trial = np.empty(TRIAL_SIZE)
        start_trial(trial, self.aims, *self.first.target, self.first.segment, *self.first.velocity, seed,
                    self.noise_record)  # fmt: skip
        attempt = Attempt()
        self._touchdown(attempt, trial, self.aims, 0, 0)
        return self.run(attempt, seed)

    def run(self, attempt: Attempt, seed: int, *, reseed: bool = False) -> Attempt:
        """Continue ``attempt`` from its last touchdown to its end; the generator goes on where it is
        (a fresh attempt: as :func:`sim_core.planning.follow.follow_plan`'s trial of ``seed``) or,
        where ``reseed``, is seeded with ``seed`` first (a continuation). ``seed`` also seeds replans."""
        trial, aims, row, replans = attempt.states[-1]
        trial = trial.copy()
        if reseed:
            seed_trial(seed)
        while trial[JUMP] < self.cap:
            may_replan = replans < self.max_replans
            outcome, row = follow(trial, aims, row, self.goal, trial[JUMP] + 1, may_replan, self.noise_record,
                                  self.record, self.sides, self.settings)  # fmt: skip
            if outcome == REPLAN:
                fresh = replanned(self.model, self.world, self.goal, trial, self.noise, seed)
                replans = replans + 1 if fresh is not None else self.max_replans
                aims, row = (fresh, 0) if fresh is not None else (aims, row)
                continue
            if outcome == REACHED:  # the goal's touchdown is kept (for its jump count) unless it is the cut's
                if trial[JUMP] > attempt.states[-1][0][JUMP]:
                    self._touchdown(attempt, trial, aims, row, replans, final=True)
                return attempt
            if outcome != CAPPED:  # a failure's code
                attempt.failed = True
                return attempt
            self._touchdown(attempt, trial, aims, row, replans)
        return attempt  # at the cap: not failed

    def _touchdown(self, attempt, trial, aims, row, replans, *, final: bool = False) -> None:
        """Keep ``trial``'s touchdown and its score: the danger of the landing just made (but at
        touchdown 0, the plan's own start) and, but at the goal (``final``), of the one the law aims
        at next, the largest so far."""
        danger = -math.inf
        if attempt.states:
            foot_y = trial[Y] - trial[ZETA0] * math.sin(trial[PSI0])
            side, segment = int(trial[SIDE]), int(trial[SEGMENT])
            danger = -landing_margin(self.sides, side, segment, foot_y, trial[PSI0], self.settings)
        if not final:
            danger = max(danger, -planned_margin(trial, aims, row, self.record, self.sides, self.settings))
        attempt.scores.append(max(danger, attempt.scores[-1]) if attempt.scores else danger)
        attempt.states.append((trial.copy(), aims, row, replans))
