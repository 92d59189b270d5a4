"""A plan from touchdown 0 to a goal height in a world: which leg commands, jump by jump, put the
feet on footholds most robustly under the robot's noise (docs/model.md §5.1, §8).

The search is a beam over the next leg's commands (a grid of ``psi0`` x ``zeta0``: the next leg may
be chosen up to lift-off, docs/model.md §2.1). Each candidate jump is run nominally and under
``samples`` draws of the noise — the coming leg's ``psi0`` (its pitch drift folded in) and
``zeta0``, and the velocity at this touchdown — the same draws for every candidate (common random
numbers, so candidates are compared on equal terms). A draw succeeds if the jump completes, the
foot lands where its touchdown does not slip at once (inside its foothold's cone) and the body
stays above the floor. **The robustness measure** is the product over the plan's jumps of each
jump's success share (a plan's estimated chance to get through, each jump judged from the nominal
state): the search keeps the ``beam`` best partial plans by that score (ties: the higher foot),
one per (foot height to 1 cm of l0, side, velocity to 0.1), and ends at the first jump whose
nominal foot reaches the goal, with the best-scored plan there. A search that finds none is run
once more with a beam of :data:`WIDEST_BEAM` (on ten default random worlds a beam of 24 found 9
ways to 1.5 m, 64 found 10).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from sim_core.model.controls import ControlSchedule, LegControl
from sim_core.model.errors import ParameterError
from sim_core.model.failures import FLOOR_HEIGHT, OK
from sim_core.model.noise import NoiseModel
from sim_core.model.params import ModelParams
from sim_core.model.validation import check_range
from sim_core.world.climb import first_touchdown
from sim_core.world.geometry import pack
from sim_core.world.stride import world_orbit_batch
from sim_core.world.world import SIDES, World

PSI0_DEG = np.arange(15.0, 45.01, 2.5)  # the next leg's angles tried [deg]
ZETA0 = np.arange(0.80, 0.961, 0.02)  # and lengths [l0]
SAMPLES, BEAM, MAX_JUMPS = 8, 24, 80
WIDEST_BEAM = 96  # the second search's, when the first finds no way to the goal
FLOOR_OF_CHANCE = 1e-3  # a jump no draw survives still scores, far below any that one does


@dataclass(frozen=True)
class PlanStep:
    """Touchdown ``jump`` of the plan: the foot on ``side``'s ``segment`` at ``target`` (x, y)
    [l0, wall coordinates], set down by a leg commanded ``(psi0, zeta0)`` [rad, l0]."""

    jump: int
    side: int
    segment: int
    target: tuple[float, float]
    leg: LegControl

    def to_dict(self) -> dict:
        return {"jump": self.jump, "side": SIDES[self.side], "segment": self.segment,
                "target": [float(self.target[0]), float(self.target[1])],
                "psi0_deg": float(math.degrees(self.leg.psi0)), "zeta0": float(self.leg.zeta0)}  # fmt: skip


@dataclass(frozen=True)
class Plan:
    """A plan: its touchdowns, whether the last reaches the goal, its score (the estimated chance
    to get through, see the module), the highest foot reached [l0] and the search's time [s]."""

    steps: tuple[PlanStep, ...]
    reaches_goal: bool
    chance: float
    highest: float
    seconds: float

    @property
    def schedule(self) -> ControlSchedule:
        """The plan's legs as a schedule: row k sets touchdown k down (climb_world replays it)."""
        return ControlSchedule.of(*(step.leg for step in self.steps))


def plan_climb(
    model: ModelParams,
    world: World,
    goal: float,
    state,
    *,
    foot_y: float = 0.0,
    noise: NoiseModel | None = None,
    samples: int = SAMPLES,
    beam: int = BEAM,
    max_jumps: int = MAX_JUMPS,
    seed: int = 0,
) -> Plan:
    """The most robust plan from touchdown 0 (the foot on the left side at ``foot_y`` [l0], the
    body arriving with ``state``) to a foot at ``goal`` [l0] or higher; ``reaches_goal`` False
    with the highest foot found when none does."""
    started = time.perf_counter()
    goal, foot_y = check_range("goal_height", goal), check_range("foot_y", foot_y)
    if goal <= foot_y:
        raise ParameterError("goal_height", f"must be above the start's foot ({foot_y:g} l0), got {goal:g} l0")
    if goal > world.top:
        raise ParameterError("goal_height", f"must be at most the world's top ({world.top:g} l0), got {goal:g} l0")
    noise = NoiseModel() if noise is None else noise
    plan = _search(model, world, goal, state, foot_y, noise, samples, beam, max_jumps, seed, started)
    if not plan.reaches_goal and beam < WIDEST_BEAM:  # a narrow beam can lose the only way up
        plan = _search(model, world, goal, state, foot_y, noise, samples, WIDEST_BEAM, max_jumps, seed, started)
    return plan


def _search(model, world, goal, state, foot_y, noise, samples, beam, max_jumps, seed, started) -> Plan:
    """One beam search (see the module)."""
    legs = np.array([(math.radians(p), z) for p in PSI0_DEG for z in ZETA0])
    draws = _draws(noise, samples, seed)
    sides = pack(world, model.mu)
    nodes = []
    for index, leg in enumerate(legs):
        row, segment = first_touchdown(model, world, ControlSchedule.of(LegControl(*leg)), state, foot_y)
        nodes.append(_Node(row, 0, segment, index, 0.0, ((row, 0, segment, index),)))
    highest, best_path = foot_y, nodes[0].path
    for _ in range(max_jumps):
        children = _expand(model, sides, legs, draws, nodes)
        if not children:
            break
        top = max(children, key=lambda child: child.foot(legs))
        if top.foot(legs) > highest:
            highest, best_path = top.foot(legs), top.path
        arrived = [child for child in children if child.foot(legs) >= goal]
        if arrived:
            chosen = max(arrived, key=lambda child: (child.score, child.foot(legs)))
            return _plan(chosen.path, legs, True, chosen.score, max(highest, chosen.foot(legs)), started)
        nodes = _keep(children, legs, beam)
    return _plan(best_path, legs, False, -math.inf, highest, started)


@dataclass(frozen=True)
class _Node:
    row: np.ndarray  # the body at this touchdown: x, y, xdot, ydot [l0, sqrt(g l0)]
    side: int
    segment: int
    leg: int  # index of the leg that set it down
    score: float  # sum of log chances so far
    path: tuple  # (row, side, segment, leg) of every touchdown so far

    def foot(self, legs) -> float:
        psi0, zeta0 = legs[self.leg]
        return float(self.row[1] - zeta0 * math.sin(psi0))


def _draws(noise: NoiseModel, samples: int, seed: int) -> np.ndarray:
    """(samples + 1, 4) draws of (psi0, zeta0, xdot, ydot) noise; row 0 the nominal (zeros)."""
    record = noise.record()
    sigma_psi0 = math.hypot(record.sigma_psi0, record.sigma_pitch)  # the pitch's step turns the leg too
    scale = np.array([sigma_psi0, record.sigma_zeta0, record.sigma_velocity, record.sigma_velocity])
    normal = np.random.default_rng(seed).standard_normal((samples, 4))
    return np.vstack([np.zeros(4), normal * scale])


def _expand(model, sides, legs, draws, nodes) -> list[_Node]:
    """Every node's jump with every next leg, under every draw: the children that land nominally."""
    per_node, per_leg = len(legs) * len(draws), len(draws)
    count = len(nodes) * per_node
    states = np.zeros((count, 2, 4))
    on_side = np.zeros((count, 2), dtype=np.int64)
    on_segment = np.zeros((count, 2), dtype=np.int64)
    schedules = np.empty((count, 2, 2))
    for i, node in enumerate(nodes):
        block = slice(i * per_node, (i + 1) * per_node)
        start = np.tile(node.row, (per_node, 1))
        start[:, 2:] += np.tile(draws[:, 2:], (len(legs), 1))  # the velocity noise at this touchdown
        states[block, 0], on_side[block, 0], on_segment[block, 0] = start, node.side, node.segment
        schedules[block, 0] = legs[node.leg]
        coming = np.repeat(legs, per_leg, axis=0) + np.tile(draws[:, :2], (len(legs), 1))
        schedules[block, 1] = np.clip(coming, [1e-3, 1e-3], [0.5 * math.pi - 1e-3, 1.0 - 1e-3])
    status, completed = np.empty(count, dtype=np.int64), np.empty(count, dtype=np.int64)
    world_orbit_batch(schedules, 0, model.record(), sides, states, on_side, on_segment, status, completed)
    landed = states[:, 1]
    held = (status == OK) & (landed[:, 1] >= FLOOR_HEIGHT) & _in_cone(sides, on_side[:, 1], on_segment[:, 1],
                                                                     schedules[:, 1, 0])  # fmt: skip
    held = held.reshape(len(nodes), len(legs), len(draws))
    chance = held[:, :, 1:].mean(axis=2) if len(draws) > 1 else held[:, :, 0].astype(float)
    children = []
    for i, node in enumerate(nodes):
        for leg in np.flatnonzero(held[i, :, 0]):  # the nominal jump lands
            k = i * per_node + leg * per_leg
            score = node.score + math.log(max(float(chance[i, leg]), FLOOR_OF_CHANCE))
            step = (landed[k].copy(), int(on_side[k, 1]), int(on_segment[k, 1]), int(leg))
            children.append(_Node(*step, score, (*node.path, step)))
    return children


def _in_cone(sides, side, segment, psi0) -> np.ndarray:
    """Whether a touchdown at ``psi0`` [rad] on ``side``'s ``segment`` holds at once (docs/model.md §8)."""
    column = np.clip(segment + 1, 0, sides.beta.shape[1] - 1)
    beta, mu = sides.beta[side, column], sides.friction[side, column]
    return np.abs(psi0 - beta) < np.arctan(mu)


def _keep(children, legs, beam: int) -> list[_Node]:
    """The ``beam`` best-scored children, one per (foot to 0.01 l0, side, velocity to 0.1)."""
    kept, seen = [], set()
    for child in sorted(children, key=lambda c: (c.score, c.foot(legs)), reverse=True):
        key = (round(child.foot(legs), 2), child.side, round(float(child.row[2]), 1), round(float(child.row[3]), 1))
        if key not in seen:
            seen.add(key)
            kept.append(child)
            if len(kept) == beam:
                break
    return kept


def _plan(path, legs, reaches, score, highest, started) -> Plan:
    steps = []
    for jump, (row, side, segment, leg) in enumerate(path):
        control = LegControl(*legs[leg])
        mirror = 1.0 if side == 0 else -1.0
        target = (
            row[0] - mirror * control.zeta0 * math.cos(control.psi0),
            row[1] - control.zeta0 * math.sin(control.psi0),
        )
        steps.append(PlanStep(jump, side, segment, target, control))
    chance = math.exp(score) if reaches else 0.0
    return Plan(tuple(steps), reaches, chance, highest, time.perf_counter() - started)
