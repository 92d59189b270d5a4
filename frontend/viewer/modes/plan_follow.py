"""Simulate mode's "Follow a plan": a stored world and a goal height; the view plans the climb
(:func:`sim_core.planning.planner.plan_climb`) and follows it with the foot-placement law under the
robot's noise (:func:`sim_core.planning.followed_path.followed_path`: ``follow_plan``'s trial of the
seed, replans included, its body's path sampled), then plays it in the world: each touchdown's
target foothold marked (green: hit, red: missed) and the next one aimed at (yellow).

Planning takes a second or a few, so it runs in a background thread; the newest request wins.
The played climb is a :class:`~frontend.viewer.recordings.Recording` drawn as replay mode draws
one (:func:`frontend.viewer.modes.painter.show_frame`), so its stream is the replay's.
"""

from __future__ import annotations

import concurrent.futures
import contextlib
import math

import numpy as np

from backend.errors import NotFound
from backend.services.view import stored_world, stored_worlds
from frontend.viewer.modes.painter import show_frame
from frontend.viewer.motion import PathClip
from frontend.viewer.recordings import Recording
from frontend.viewer.world_slabs import LEGEND
from sim_core import PhysicalParams
from sim_core.model.errors import ParameterError
from sim_core.model.noise import NO_NOISE, NoiseModel
from sim_core.model.trajectory import STANCE
from sim_core.model.walls import walls_of
from sim_core.planning.followed_path import FollowedPath, followed_path
from sim_core.planning.launch import start_velocity
from sim_core.planning.planner import plan_climb
from sim_core.world.files import world_from_document
from sim_core.world.world import SIDES, World

NO_WORLD = "(none: the sliders, parallel walls)"
SAMPLE_RATE = 60.0  # per sqrt(l0/g), as a replay simulated again (recordings.REPLAY_SAMPLE_RATE)


def followed_recording(path: FollowedPath, world: World, robot: PhysicalParams, label: str) -> Recording:
    """A followed plan's path as a recording at ``robot``'s size, in ``world``."""
    columns, length, time_scale = path.columns, robot.scales.length, robot.scales.time
    jump, phase = columns["jump"].astype(int), columns["phase"].astype(int)
    clip = PathClip(
        time=columns["time"] * time_scale, x=columns["x"] * length, y=columns["y"] * length,
        foot_x=columns["foot_x"] * length, foot_y=columns["foot_y"] * length, zeta=columns["zeta"] * length,
        phase=phase, leg_wall=walls_of(jump + (phase != STANCE)), jump=jump,
    )  # fmt: skip
    count = len(path.touchdown_times)
    feet_y = path.touchdowns[:count, 1] - path.legs[:count, 1] * np.sin(path.legs[:count, 0])
    feet_x = path.touchdowns[:count, 0] - np.where(path.sides[:count] == 0, 1.0, -1.0) * path.legs[:count, 1] * np.cos(
        path.legs[:count, 0]
    )
    touchdowns = np.column_stack([path.touchdown_times * time_scale, walls_of(np.arange(count)), feet_y * length])
    return Recording(0, "plan", label, clip, robot, None, touchdowns, world=world,
                     world_mu=robot.to_model().mu, touchdown_x=feet_x * length)  # fmt: skip


class PlanFollow:
    """The folder and the played climb; ``active`` while a followed plan is on show."""

    def __init__(self, mode, sessions, robot: PhysicalParams):
        self.mode, self.sessions, self.robot = mode, sessions, robot
        self.scene = mode.scene
        gui = mode.client.gui
        with gui.add_folder("Follow a plan in a world", expand_by_default=False):
            self.gui_world = gui.add_dropdown("World", (NO_WORLD,), initial_value=NO_WORLD)
            self.gui_refresh = gui.add_button("Refresh worlds")
            self.gui_goal = mode._ranged_slider("goal [m]", 0.1, 5.0, 0.05, 0.6, hint="the foot's height to reach")
            self.gui_seed = mode._ranged_number("Seed", 1, low=0, high=2**31 - 1)
            self.gui_noise = gui.add_checkbox("Noise", initial_value=True, hint="the robot's default noise")
            self.gui_go = gui.add_button("Plan & follow")
        self.gui_refresh.on_click(lambda _event: self.refresh())
        self.gui_go.on_click(lambda _event: self.request())
        self._worker = concurrent.futures.ThreadPoolExecutor(max_workers=1, thread_name_prefix="plan")
        self._generation = 0
        self.note = ""
        self.recording: Recording | None = None
        self.path: FollowedPath | None = None
        self.active, self.time, self._marked = False, 0.0, (0, 0)
        self.refresh()

    def refresh(self) -> None:
        """List the stored worlds (newest first) in the dropdown."""
        worlds = [] if self.sessions is None else stored_worlds(self.sessions)
        self.gui_world.options = (NO_WORLD, *(f"{world_id}: {name}" for world_id, name in worlds))

    def request(self) -> None:
        """Plan and follow in the chosen world, in the background; "none" goes back to the sliders."""
        with self.mode.lock:
            problem = self.mode._out_of_range((self.gui_goal, self.gui_seed))
            if problem is not None:
                self.note = f"**Not used:** {problem}"
                return
            self._generation += 1
            if self.gui_world.value == NO_WORLD:
                self.stop()
                return
            generation, world_id = self._generation, int(self.gui_world.value.split(":")[0])
            goal_m, seed, noisy = float(self.gui_goal.value), int(self.gui_seed.value), bool(self.gui_noise.value)
            self.note = f"planning in world {world_id} to {goal_m:g} m…"
        with contextlib.suppress(RuntimeError):  # closed: the browser has gone
            self._worker.submit(self._plan, generation, world_id, goal_m, seed, noisy)

    def _plan(self, generation: int, world_id: int, goal_m: float, seed: int, noisy: bool) -> None:
        recording, path, note = None, None, ""
        try:
            world = world_from_document(stored_world(self.sessions, world_id))
            model, l0 = self.robot.to_model(), self.robot.leg_length
            noise, goal = NoiseModel() if noisy else NO_NOISE, goal_m / l0
            plan = plan_climb(model, world, goal, start_velocity(model), noise=noise, seed=seed)
            path = followed_path(model, world, plan, goal, noise, seed, sample_rate=SAMPLE_RATE)
            label = f"world {world_id} {world.name!r}, goal {goal_m:g} m, seed {seed}"
            recording = followed_recording(path, world, self.robot, label)
            planned = "reaches the goal" if plan.reaches_goal else f"gets to {plan.highest * l0:.2f} m at best"
            note = f"plan: {len(plan.steps) - 1} jumps, {planned}, estimated chance {plan.chance:.2f}"
        except (NotFound, ParameterError, ValueError) as error:
            note = f"**Cannot plan:** {error}"
        with self.mode.lock:
            if generation != self._generation:
                return
            self.note, self.recording, self.path = note, recording, path
            if recording is not None:
                self.active, self.time, self._marked = True, 0.0, (0, 0)
                self.scene.clear_history()

    def stop(self) -> None:
        """Back to the sliders' climb between the parallel walls."""
        self.active, self.recording, self.path = False, None, None
        self.scene.clear_history()
        self.scene.set_world(None)

    def restart(self) -> None:
        self.time, self._marked = 0.0, (0, 0)
        self.scene.clear_history()

    def close(self) -> None:
        self._generation += 1
        self._worker.shutdown(wait=False, cancel_futures=True)

    def frame(self, dt: float, speed: float, playing: bool) -> None:
        recording, path = self.recording, self.path
        if playing:  # to the last touchdown (its landing's last sample is just before it)
            self.time = min(self.time + dt * speed, max(recording.duration, float(recording.touchdowns[-1, 0])))
        if self.scene.touchdown_markers.count == 0:  # the scene started afresh (a mode chosen again)
            self._marked = (0, 0)
        before = self._marked[0]
        self._marked = show_frame(self.scene, recording, None, self.time, self._marked)
        l0 = self.robot.leg_length
        for k in range(before, self._marked[0]):  # touchdown k passed: its target, hit or missed
            if not math.isnan(path.aims[k, 0]):
                self.scene.add_target(path.aims[k, 1] * l0, path.aims[k, 2] * l0, hit=bool(path.hits[k]))
        upcoming = self._marked[0]
        if upcoming < len(path.aims) and not math.isnan(path.aims[upcoming, 0]):
            self.scene.show_aim(path.aims[upcoming, 1] * l0, path.aims[upcoming, 2] * l0)
        else:
            self.scene.show_aim(None, None)

    def readout(self) -> str:
        path = self.path
        if path is None:
            return self.note
        done = self._marked[0]
        hits = int(path.hits[:done].sum())
        aimed = int(np.count_nonzero(~np.isnan(path.aims[:done, 0])))
        words = []
        if done:
            k = done - 1
            side = SIDES[int(path.sides[k])]
            hit = "hit" if path.hits[k] else ("missed" if not math.isnan(path.aims[k, 0]) else "no target")
            words.append(f"touchdown {k}: {side} segment {int(path.segments[k])} — **{hit}**")
        if done >= len(path.touchdown_times):
            end = "reached the goal" if path.reached else ("failed" if path.failed else "stopped at the cap")
            words.append(f"**{end}** after {path.jumps} jumps")
        return (f"{self.note}  \n**Following:** {self.recording.label}  \nfootholds hit {hits}/{aimed} · "
                f"replans {path.replans} · " + " · ".join(words) + f"  \n{LEGEND}")  # fmt: skip
