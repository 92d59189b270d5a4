"""A plan from touchdown 0 to a goal height in a world: which leg commands, jump by jump, put the
feet on footholds most robustly under the robot's noise (docs/model.md §5.1, §8), in a form the
foot-placement law can follow (:mod:`sim_core.planning.follow`).

The search is a beam over the next leg's commands (a grid of ``psi0`` x ``zeta0``: the next leg may
be chosen up to lift-off, docs/model.md §2.1). Each candidate jump is run nominally and under
``samples`` draws of the noise — the coming leg's ``psi0`` (its pitch drift folded in) and
``zeta0``, the velocity at this touchdown, and the length of the leg stood on (the angle then the
one that keeps its foot on the wall below the body: what the law cannot see,
:func:`sim_core.control.placement.leg_on_wall`) — the same draws for every candidate (common random
numbers, so candidates are compared on equal terms). A candidate is kept only if its nominal foot
lands with the placement law's margins (from the foothold's ends and inside its cone,
:class:`sim_core.control.laws.placement.PlacementSettings`), so that the law, on the plan, sends the
plan's own legs. A draw succeeds if the jump completes, the foot lands on the nominal's foothold
inside its cone and the body stays above the floor. **The robustness measure** is the product over
the plan's jumps of each jump's success share (a plan's estimated chance to get through, each jump
judged from the nominal state): the search keeps the ``beam`` best partial plans by that score
(ties: the higher foot), one per (foot height to 1 cm of l0, side, velocity to 0.1), and ends at
the first jump whose nominal foot reaches the goal, with the best-scored plan there. A search that
finds none is run once more with a beam of :data:`WIDEST_BEAM`. :func:`replan` plans the same way
from a touchdown under way.

What the measure misses (docs/analyses.md, "Foot placement"): each jump is judged from the plan's
own state, so a plan whose every jump is sure can still fail once noise has moved the robot off
it; measured, the chance overstates how often the law gets through.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from sim_core.control.laws.placement import PlacementSettings
from sim_core.model.controls import ControlSchedule, LegControl
from sim_core.model.failures import FLOOR_HEIGHT, OK
from sim_core.model.noise import NoiseModel
from sim_core.model.params import ModelParams
from sim_core.planning.goals import check_goal
from sim_core.planning.landings import in_cone, noise_draws, standing_legs, with_margins
from sim_core.planning.launch import launch_velocity
from sim_core.world.climb import first_touchdown
from sim_core.world.geometry import pack
from sim_core.world.stride import world_flight, world_orbit_batch
from sim_core.world.world import SIDES, World

PSI0_DEG = np.arange(15.0, 45.01, 2.5)  # the next leg's angles tried [deg]
ZETA0 = np.arange(0.80, 0.961, 0.02)  # and lengths [l0]
SAMPLES, BEAM, MAX_JUMPS = 8, 24, 80
WIDEST_BEAM = 96  # the second search's, when the first finds no way to the goal
FLOOR_OF_CHANCE = 1e-3  # a jump no draw survives still scores, far below any that one does
LEGS = np.array([(math.radians(p), z) for p in PSI0_DEG for z in ZETA0])  # the next legs tried


@dataclass(frozen=True)
class PlanStep:
    """Touchdown ``jump`` of the plan: the foot on ``side``'s ``segment`` at ``target`` (x, y)
    [l0, wall coordinates], set down by a leg commanded ``(psi0, zeta0)`` [rad, l0]."""

    jump: int
    side: int
    segment: int
    target: tuple[float, float]
    leg: LegControl
    velocity: tuple[float, float]  # the body's (xdot, ydot) at this touchdown [sqrt(g l0)], wall coordinates

    def to_dict(self) -> dict:
        return {"jump": self.jump, "side": SIDES[self.side], "segment": self.segment,
                "target": [float(self.target[0]), float(self.target[1])],
                "psi0_deg": float(math.degrees(self.leg.psi0)), "zeta0": float(self.leg.zeta0),
                "velocity": [float(self.velocity[0]), float(self.velocity[1])]}  # fmt: skip


@dataclass(frozen=True)
class Plan:
    """A plan: its touchdowns, whether the last reaches the goal, its score (the estimated chance
    to get through, see the module), the highest foot reached [l0] and the search's time [s]."""

    steps: tuple[PlanStep, ...]
    reaches_goal: bool
    chance: float
    highest: float
    seconds: float

    def to_dict(self, metres: float) -> dict:
        """``parkour plan --json`` (l0 = ``metres`` [m]; the targets in l0, as the world file's frame)."""
        return {"reaches_goal": self.reaches_goal, "plan": [step.to_dict() for step in self.steps],
                "seconds": self.seconds, "highest_m": self.highest * metres, "chance": self.chance}  # fmt: skip

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
    launch_gait: bool = False,
) -> Plan:
    """The most robust plan from touchdown 0 (the foot on the left side at ``foot_y`` [l0], the
    body arriving with ``state``) to a foot at ``goal`` [l0] or higher; ``reaches_goal`` False
    with the highest foot found when none does. ``launch_gait``: the body arrives instead with the
    velocity of the gait of touchdown 0's own leg — as a robot launched on that leg does (the
    virtual robot, backend/robot/climber.py); a leg without a gait is not tried."""
    started = time.perf_counter()
    goal, foot_y = check_goal(world, goal, foot_y, footholds=False)
    nodes = []
    for leg in LEGS:
        schedule = ControlSchedule.of(LegControl(*leg))
        if launch_gait:
            state = launch_velocity(model, schedule)
            if state is None:
                continue
        row, segment = first_touchdown(model, world, schedule, state, foot_y)
        nodes.append(_Node(row, 0, segment, tuple(leg), 0.0, ((row, 0, segment, tuple(leg)),)))
    return _best_plan(model, world, goal, nodes, foot_y, noise, samples, beam, max_jumps, seed, started)


def replan(model: ModelParams, world: World, goal: float, touchdown, *, liftoff=None, noise: NoiseModel | None = None,
           samples: int = SAMPLES, beam: int = BEAM, max_jumps: int = MAX_JUMPS, seed: int = 0) -> Plan:  # fmt: skip
    """The most robust plan from a touchdown under way to a foot at ``goal`` [l0]: ``touchdown`` is
    ``(row, side, segment, leg)``, the body's ``x, y, xdot, ydot`` there (wall coordinates), its
    side and segment, and the leg ``(psi0, zeta0)`` [rad, l0] it stands on; ``liftoff``: the
    lift-off that stance ends in, tracked (``x, y, xdot, ydot``), where known — then the first
    jump is planned from it. The plan's row 0 is this touchdown (its ``jump`` 0)."""
    started = time.perf_counter()
    noise = NoiseModel() if noise is None else noise
    row, side, segment, leg = touchdown
    row, leg = np.asarray(row, dtype=float), (float(leg[0]), float(leg[1]))
    node = _Node(row, int(side), int(segment), leg, 0.0, ((row, int(side), int(segment), leg),))
    foot = node.foot()
    if goal <= foot:
        return _plan(node.path, True, 0.0, foot, started)
    if liftoff is None:
        return _best_plan(model, world, goal, [node], foot, noise, samples, beam, max_jumps, seed, started)
    sides = pack(world, model.mu)
    children = _flights(sides, node, tuple(float(v) for v in liftoff), noise_draws(noise, samples, seed),
                        PlacementSettings())  # fmt: skip
    if not children:
        return _plan(node.path, False, -math.inf, foot, started)
    return _best_plan(model, world, goal, _keep(children, beam), foot, noise, samples, beam, max_jumps - 1, seed,
                      started)  # fmt: skip


def _flights(sides, node, liftoff, draws, settings) -> list[_Node]:
    """``node``'s children from its lift-off, tracked: each leg's flight, nominal and under the
    draws of the coming leg's noise (the stance is over: its noise is seen)."""
    children = []
    for leg in LEGS:
        landings = []
        for draw in draws:
            coming = np.clip(leg + draw[:2], [1e-3, 1e-3], [0.5 * math.pi - 1e-3, 1.0 - 1e-3])
            status, x, y, xdot, ydot, segment, _ = world_flight(*liftoff, node.side, coming[0], coming[1], sides)
            landings.append((status, np.array([x, y, xdot, ydot]), segment, coming))
        status, landed, segment, _ = landings[0]
        other = 1 - node.side
        if status != OK or landed[1] < FLOOR_HEIGHT or not in_cone(sides, other, segment, leg[0]):
            continue
        foot = landed[1] - leg[1] * math.sin(leg[0])
        if not with_margins(sides, np.array([other]), np.array([segment]), np.array([foot]), np.array([leg[0]]),
                             settings)[0]:  # fmt: skip
            continue
        held = [s == OK and row[1] >= FLOOR_HEIGHT and seg == segment and in_cone(sides, other, seg, c[0])
                for s, row, seg, c in landings[1:]]  # fmt: skip
        chance = float(np.mean(held)) if held else 1.0
        step = (landed, other, int(segment), (float(leg[0]), float(leg[1])))
        children.append(_Node(*step, node.score + math.log(max(chance, FLOOR_OF_CHANCE)), (*node.path, step)))
    return children


def _best_plan(model, world, goal, nodes, foot_y, noise, samples, beam, max_jumps, seed, started) -> Plan:
    noise = NoiseModel() if noise is None else noise
    plan = _search(model, world, goal, nodes, foot_y, noise, samples, beam, max_jumps, seed, started)
    if not plan.reaches_goal and beam < WIDEST_BEAM:  # a narrow beam can lose the only way up
        plan = _search(model, world, goal, nodes, foot_y, noise, samples, WIDEST_BEAM, max_jumps, seed, started)
    return plan


def _search(model, world, goal, nodes, foot_y, noise, samples, beam, max_jumps, seed, started) -> Plan:
    """One beam search (see the module) from ``nodes``, the touchdowns it may start from."""
    legs = LEGS
    draws = noise_draws(noise, samples, seed)
    sides = pack(world, model.mu)
    highest, best_path = max(foot_y, max(node.foot() for node in nodes)), max(nodes, key=_Node.foot).path
    arrived = [node for node in nodes if len(node.path) > 1 and node.foot() >= goal]  # a replan's first flights
    if arrived:
        chosen = max(arrived, key=lambda node: (node.score, node.foot()))
        return _plan(chosen.path, True, chosen.score, highest, started)
    for _ in range(max_jumps):
        children = _expand(model, sides, legs, draws, nodes, PlacementSettings())
        if not children:
            break
        top = max(children, key=_Node.foot)
        if top.foot() > highest:
            highest, best_path = top.foot(), top.path
        arrived = [child for child in children if child.foot() >= goal]
        if arrived:
            chosen = max(arrived, key=lambda child: (child.score, child.foot()))
            return _plan(chosen.path, True, chosen.score, max(highest, chosen.foot()), started)
        nodes = _keep(children, beam)
    return _plan(best_path, False, -math.inf, highest, started)


@dataclass(frozen=True)
class _Node:
    row: np.ndarray  # the body at this touchdown: x, y, xdot, ydot [l0, sqrt(g l0)]
    side: int
    segment: int
    leg: tuple[float, float]  # (psi0, zeta0) of the leg that set it down [rad, l0]
    score: float  # sum of log chances so far
    path: tuple  # (row, side, segment, leg) of every touchdown so far

    def foot(self) -> float:
        psi0, zeta0 = self.leg
        return float(self.row[1] - zeta0 * math.sin(psi0))


def _expand(model, sides, legs, draws, nodes, settings) -> list[_Node]:
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
        start[:, 2:] += np.tile(draws[:, 2:4], (len(legs), 1))  # the velocity noise at this touchdown
        states[block, 0], on_side[block, 0], on_segment[block, 0] = start, node.side, node.segment
        schedules[block, 0] = np.tile(standing_legs(sides, node, draws), (len(legs), 1))
        coming = np.repeat(legs, per_leg, axis=0) + np.tile(draws[:, :2], (len(legs), 1))
        schedules[block, 1] = np.clip(coming, [1e-3, 1e-3], [0.5 * math.pi - 1e-3, 1.0 - 1e-3])
    status, completed = np.empty(count, dtype=np.int64), np.empty(count, dtype=np.int64)
    world_orbit_batch(schedules, 0, model.record(), sides, states, on_side, on_segment, status, completed)
    landed = states[:, 1]
    held = (status == OK) & (landed[:, 1] >= FLOOR_HEIGHT) & in_cone(sides, on_side[:, 1], on_segment[:, 1],
                                                                     schedules[:, 1, 0])  # fmt: skip
    held = held.reshape(len(nodes), len(legs), len(draws))
    nominal = np.arange(0, count, len(draws))
    placeable = with_margins(sides, on_side[nominal, 1], on_segment[nominal, 1],
                              landed[nominal, 1] - schedules[nominal, 1, 1] * np.sin(schedules[nominal, 1, 0]),
                              schedules[nominal, 1, 0], settings).reshape(len(nodes), len(legs))  # fmt: skip
    landed_on = on_segment[:, 1].reshape(len(nodes), len(legs), len(draws))
    held[:, :, 1:] &= landed_on[:, :, 1:] == landed_on[:, :, :1]  # a draw counts on the nominal's foothold only
    chance = held[:, :, 1:].mean(axis=2) if len(draws) > 1 else held[:, :, 0].astype(float)
    children = []
    for i, node in enumerate(nodes):
        for leg in np.flatnonzero(held[i, :, 0] & placeable[i]):  # the nominal jump lands, with margins
            k = i * per_node + leg * per_leg
            score = node.score + math.log(max(float(chance[i, leg]), FLOOR_OF_CHANCE))
            step = (
                landed[k].copy(),
                int(on_side[k, 1]),
                int(on_segment[k, 1]),
                (float(legs[leg, 0]), float(legs[leg, 1])),
            )
            children.append(_Node(*step, score, (*node.path, step)))
    return children


def _keep(children, beam: int) -> list[_Node]:
    """The ``beam`` best-scored children, one per (foot to 0.01 l0, side, velocity to 0.1)."""
    kept, seen = [], set()
    for child in sorted(children, key=lambda c: (c.score, c.foot()), reverse=True):
        key = (round(child.foot(), 2), child.side, round(float(child.row[2]), 1), round(float(child.row[3]), 1))
        if key not in seen:
            seen.add(key)
            kept.append(child)
            if len(kept) == beam:
                break
    return kept


def _plan(path, reaches, score, highest, started) -> Plan:
    steps = []
    for jump, (row, side, segment, leg) in enumerate(path):
        control = LegControl(*leg)
        mirror = 1.0 if side == 0 else -1.0
        target = (
            row[0] - mirror * control.zeta0 * math.cos(control.psi0),
            row[1] - control.zeta0 * math.sin(control.psi0),
        )
        steps.append(PlanStep(jump, side, segment, target, control, (float(row[2]), float(row[3]))))
    chance = math.exp(score) if reaches else 0.0
    return Plan(tuple(steps), reaches, chance, highest, time.perf_counter() - started)
