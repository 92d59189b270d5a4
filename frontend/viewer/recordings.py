"""Stored runs as the 3D view replays them: a :class:`Recording` per run.

- ``sim`` runs: the stored sampled path, or, when the run kept none, the same path simulated
  again from its stored model, controls and start state (the simulator is deterministic);
- ``robot`` runs: the tracker frames (body only: the camera does not see the legs) and the
  touchdowns found live, each marked in a world where its foot met the world's side at its
  height (:func:`frontend.viewer.modes.live_world.foot_on_side`, as live mode marks it);
- ``replay`` runs: their source robot run's frames with the touchdowns found again.

A run that climbed a stored world carries that world (drawn in place of the parallel walls,
:meth:`frontend.viewer.scene.ChuteScene.set_world`); a sim run's path is then the world's
(:func:`sim_core.world.trajectory.simulate_world_trajectory`, when none was stored), never the
parallel walls'.

Simulated runs are nondimensional; they are shown at the paper robot's size (its ``l0``, mass
and ``g``), heights from the chute's floor as every climb has them (:mod:`sim_core.climb.sequencer`): the
first foot touches at the floor.
"""

from __future__ import annotations

import datetime
import math
from dataclasses import dataclass

import numpy as np

from backend.errors import Conflict
from backend.services.view import StoredPath, stored_path
from frontend.viewer.modes.live_world import foot_on_side
from frontend.viewer.motion import TRAIL_STRIDE, PathClip
from sim_core import ControlSchedule, LegControl, ModelParams, PhysicalParams, get_preset, simulate_trajectory
from sim_core.climb.sequencer import start_height
from sim_core.model.trajectory import STANCE
from sim_core.model.walls import Wall, walls_of
from sim_core.world.files import world_from_document
from sim_core.world.trajectory import simulate_world_trajectory
from sim_core.world.world import World

# Per sqrt(l0/g), when a stored sim run has no path of its own: the panel's "Save run" rate (about
# 160 samples/s at the paper robot's size). The simulation costs the same at any rate; trails and
# a shared file's size grow with it.
REPLAY_SAMPLE_RATE = 60.0
MAX_TRAIL_SECONDS = 5.0  # the trail of the jump under way reaches back this far at most (a run with no touchdowns)


@dataclass(frozen=True)
class Recording:
    """A stored run ready to show.

    Attributes:
        run_id, kind, label: which run, and a line that names it.
        description: a sentence that tells what the run was (controls, jumps, climb, date), as text.
        clip: the path, time from 0 at the start of the run.
        robot: the robot it is shown at (walls, leg length, energy colours).
        legs: the left and right legs' controls (the idle leg's pose), or None for tracker data.
        touchdowns: shape (n, 3): time [s], wall (a :class:`Wall` value: -1 left, +1 right), foot height [m].
        world: the world it climbed (``l0`` units; None: the parallel walls), ``world_mu`` the
            friction where the world leaves it open; ``touchdown_x``: shape (n,), each touchdown's
            foot ``x`` [m] (None: on the parallel walls).
    """

    run_id: int
    kind: str
    label: str
    clip: PathClip
    robot: PhysicalParams
    legs: tuple[LegControl, LegControl] | None
    touchdowns: np.ndarray
    description: str = ""
    world: World | None = None
    world_mu: float = math.inf
    touchdown_x: np.ndarray | None = None

    def touchdown_marker(self, k: int) -> tuple[int, float, float | None]:
        """Touchdown ``k``'s marker: its wall, foot height [m] and foot ``x`` [m] (None: on the wall)."""
        _time, wall, foot_height = self.touchdowns[k]
        return int(wall), float(foot_height), None if self.touchdown_x is None else float(self.touchdown_x[k])

    @property
    def duration(self) -> float:
        return self.clip.end

    def touchdowns_until(self, t):
        """How many touchdowns happened at or before ``t`` [s] (a float or an array of them)."""
        return np.searchsorted(self.touchdowns[:, 0], t, side="right")

    def trail_span(self, t):
        """The body's trail at ``t`` [s] (a float or an array): samples ``[lo, hi)`` of the clip, from
        the last touchdown at or before ``t`` (the sample before it) but at most ``MAX_TRAIL_SECONDS``
        back, to ``t``. The trail drawn is every ``TRAIL_STRIDE``-th of them from ``lo``."""
        t = np.asarray(t, dtype=float)
        last_touchdown = np.r_[-np.inf, self.touchdowns[:, 0]][self.touchdowns_until(t)]
        since = np.maximum(last_touchdown, t - MAX_TRAIL_SECONDS)
        lo = np.maximum(np.searchsorted(self.clip.time, since, side="right") - 1, 0)
        hi = np.searchsorted(self.clip.time, t, side="right")
        return lo, hi

    def trail(self, t: float) -> np.ndarray:
        """The body's trail at ``t`` [s] (:meth:`trail_span`), shape (n, 2)."""
        lo, hi = (int(v) for v in self.trail_span(t))
        return np.column_stack([self.clip.x[lo:hi:TRAIL_STRIDE], self.clip.y[lo:hi:TRAIL_STRIDE]])

    def jump_trail(self, k: int) -> np.ndarray:
        """The body's path from touchdown ``k - 1`` to touchdown ``k`` (k >= 1), shape (n, 2): the trail
        a finished jump leaves."""
        since, until = self.touchdowns[k - 1, 0], self.touchdowns[k, 0]
        return self.clip.body_until(until, since=since)[::TRAIL_STRIDE]

    def idle_leg(self, leg_wall: Wall) -> LegControl | None:
        """Controls of the leg not drawn by the pose (it reaches for the other wall)."""
        if self.legs is None:
            return None
        return self.legs[0] if Wall(leg_wall).other == Wall.LEFT else self.legs[1]


def load_recording(sessions, run_id: int) -> Recording:
    """The stored run ``run_id`` as a :class:`Recording` (read by
    :func:`backend.services.view.stored_path`).

    Raises NotFound when there is no such run, Conflict when it has nothing to show
    (:mod:`backend.errors`).
    """
    run = stored_path(sessions, run_id)
    if run.kind == "sim":
        return _sim_recording(run)
    return _tracker_recording(run)


def _model_of(run: StoredPath) -> ModelParams:
    fields = {name: value for name, value in run.model.items() if name in ModelParams.__dataclass_fields__}
    if fields.get("mu") is None:
        fields["mu"] = math.inf
    return ModelParams(**fields)


def _legs(run: StoredPath) -> tuple[LegControl, LegControl]:
    pairs = [LegControl.from_degrees(*pair) for pair in run.controls]
    return pairs[0], pairs[1 % len(pairs)]


def _label(run: StoredPath) -> str:
    controls = ", ".join(f"{psi:g}°:{zeta:g}" for psi, zeta in run.controls)
    world = "" if run.world is None else f", world {run.world_id} {run.world.get('name', '')!r}"
    return f"run {run.run_id} ({run.kind}, {controls}{world})"


KIND_WORDS = {"sim": "simulated", "robot": "on the robot", "replay": "a robot run analysed again"}


def _controls_words(controls: list) -> str:
    """A control schedule as the panel says it: one pair for both legs, two for left and right."""
    pairs = [f"psi0 {psi:g}°, zeta0 {zeta:g} l0" for psi, zeta in controls]
    if len(pairs) == 1:
        return f"both legs {pairs[0]}"
    if len(pairs) == 2:
        return f"left {pairs[0]}; right {pairs[1]}"
    return "jump by jump in turn " + "; ".join(pairs)


def describe(run: StoredPath) -> str:
    """What run ``run`` was, in a sentence: its kind, controls, jumps, how it was driven and how it
    ended (as History lists them), climb and date."""
    controls = _controls_words(run.controls)
    done = "" if run.jumps_completed is None else f", {run.jumps_completed} done"
    parts = [f"ParkourLab run {run.run_id}, {KIND_WORDS.get(run.kind, run.kind)}", controls, f"{run.jumps} jumps{done}"]
    if run.loop == "closed":
        target = "" if run.target is None else f", target {run.target:.3g} m"
        parts.append(f"closed loop ({run.controller or 'pid'}{target})")
    elif run.loop == "open" and run.kind != "sim":
        parts.append("open loop")
    if run.end_reason or run.status == "failed":
        parts.append(f"ended: {run.end_reason or run.status}")
    if run.climb is not None:
        parts.append(f"climb {run.climb:.3f} l0")
    if run.created_at is not None:
        when = run.created_at if run.created_at.tzinfo else run.created_at.replace(tzinfo=datetime.UTC)
        parts.append(f"stored {when.astimezone(datetime.UTC):%Y-%m-%d %H:%M} UTC")
    return ": ".join(parts[:2]) + "; " + "; ".join(parts[2:]) + "."


def _sim_recording(run: StoredPath) -> Recording:
    paper = get_preset("paper")
    robot = PhysicalParams.from_model(
        _model_of(run), mass=paper.mass, leg_length=paper.leg_length, gravity=paper.gravity
    )
    world = None if run.world is None else world_from_document(run.world)
    schedule = ControlSchedule.from_degrees(run.controls)
    if run.path is not None:
        columns = run.path
    elif world is not None:  # simulated again in its world, as quick_calls._world_climb did
        columns = simulate_world_trajectory(
            robot.to_model(), world, schedule, run.start_state, run.jumps, sample_rate=REPLAY_SAMPLE_RATE
        )[0].columns()
    else:
        columns = simulate_trajectory(
            robot.to_model(), schedule, run.start_state, run.jumps, sample_rate=REPLAY_SAMPLE_RATE
        ).columns()
    if columns["time"].size == 0:
        raise Conflict(f"run {run.run_id} failed at its first touchdown: there is no path to show")
    length, time_scale = robot.scales.length, robot.scales.time
    jump, phase = columns["jump"].astype(int), columns["phase"].astype(int)
    # The drawn leg reaches for the stance wall in stance and for the next wall in flight.
    leg_wall = walls_of(jump + (phase != STANCE))
    # The map's stored path has y = 0 at the first touchdown; a world's is from the world's floor.
    first = start_height(_legs(run)[0], robot) if world is None else 0.0
    clip = PathClip(
        time=columns["time"] * time_scale,
        x=columns["x"] * length,
        y=first + columns["y"] * length,
        foot_x=columns["foot_x"] * length,
        foot_y=first + columns["foot_y"] * length,
        zeta=columns["zeta"] * length,
        phase=phase,
        leg_wall=leg_wall,
        jump=jump,
    )
    stance_starts = np.flatnonzero((phase == STANCE) & np.r_[True, np.diff(jump) != 0])
    touchdowns = np.column_stack([clip.time[stance_starts], clip.leg_wall[stance_starts], clip.foot_y[stance_starts]])
    return Recording(run.run_id, run.kind, _label(run), clip, robot, _legs(run), touchdowns, describe(run),
                     world=world, world_mu=robot.to_model().mu,
                     touchdown_x=None if world is None else clip.foot_x[stance_starts])  # fmt: skip


def _tracker_recording(run: StoredPath) -> Recording:
    frames = run.path  # stored_path has refused a robot or replay run without frames
    if frames["time"].size == 0:
        raise Conflict(f"run {run.run_id} has no tracker frames to replay")
    t0 = float(frames["time"][0])
    clip = PathClip.from_body(frames["time"] - t0, frames["x"], frames["y"])
    touchdowns = np.array([[td["time"] - t0, td["wall"], td["foot_height"]] for td in run.touchdowns]).reshape(-1, 3)
    world = None if run.world is None else world_from_document(run.world)
    robot = get_preset("paper")  # the world was read in l0 at its leg length (backend.services.view.VIEW_PRESET)
    # In a world each foot is marked where it met its side at its height, as live mode marks it.
    feet = None if world is None else np.array([foot_on_side(world, robot.leg_length, int(wall), height)
                                                for _time, wall, height in touchdowns])  # fmt: skip
    return Recording(run.run_id, run.kind, _label(run), clip, robot, None, touchdowns, describe(run),
                     world=world, world_mu=robot.to_model().mu, touchdown_x=feet)  # fmt: skip
