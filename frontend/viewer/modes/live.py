"""Live mode: the robot as the tracker sees it, and the model's prediction of the jump under way.

It reads the one robot through the robot service's immutable snapshots (``run_snapshot()``,
``tracker``, ``status()``), so everyone who chooses it sees the same robot; it never commands
the robot. The ghost is the model's jump from each touchdown the live run detected, predicted
with the paper's model or a calibration (:mod:`frontend.viewer.ghost_models`): between the
parallel walls (:func:`frontend.viewer.simulated_climb.model_jump`), or, for a run in a stored world
(drawn in that world, with the plan it follows if any: :mod:`frontend.viewer.modes.live_world`),
in that world's sides (:func:`frontend.viewer.world_ghost.world_jump`). A jump the model fails is
drawn up to the failure, and the readout says why.
"""

from __future__ import annotations

import numpy as np
import viser

from backend.services.view import commanded
from frontend.viewer.ghost_models import BASE, ghost_model, model_choices, realised
from frontend.viewer.modes import Mode
from frontend.viewer.modes.live_world import LiveWorld
from frontend.viewer.motion import TRAIL_STRIDE, PathClip
from frontend.viewer.scene import TOUCHDOWN_MARKERS, ChuteScene
from frontend.viewer.simulated_climb import JumpPlan, model_jump
from frontend.viewer.world_ghost import in_leg_lengths, world_jump


class LiveMode(Mode):
    """The robot as the tracker sees it, and the model's prediction of the jump under way."""

    name = "live"

    def __init__(self, client: viser.ClientHandle, scene: ChuteScene, lock, robot_service, sessions=None):
        super().__init__(client, scene, lock)
        self.robot_service = robot_service
        self.sessions = sessions
        gui = client.gui
        with gui.add_folder("Live", visible=False) as self.folder:
            self.gui_ghost = gui.add_checkbox(
                "Model ghost", initial_value=True, hint="the model's jump from each touchdown"
            )
            self.gui_ghost_model = gui.add_dropdown(
                "Ghost model", model_choices(sessions), initial_value=BASE,
                hint="the paper's model, or a calibration fitted to the robot's runs (docs/calibration.md)",
            )  # fmt: skip
            self.gui_readout = gui.add_markdown("")
        self.gui_ghost_model.on_update(lambda _event: self.use_ghost_model(self.gui_ghost_model.value))
        self.ghost_model = ghost_model(sessions, BASE)
        self._ghosts: dict[int, JumpPlan] = {}
        self._marked = 0
        self._run = None
        self.run_world = LiveWorld()  # the world the latest run climbs, read once per run
        self.last_error: float | None = None
        # The robot's trail is streamed (ChuteScene.live_trail) from the tracker's frames by their
        # index (PoseHistory.count), not their time: the camera's clock need not restart at a
        # run, and the virtual robot's does. The run's first frame this view knows, and the next
        # frame to draw (None: draw the run's again, from the first).
        self._tracker = None
        self._trail_from, self._trail_next = 0, None
        self._ghost_drawn: tuple[int, int] = (-1, 0)  # the ghost's jump, and its trail's points drawn

    def activate(self) -> None:
        super().activate()
        # Choosing a mode clears the scene: this run's markers and trail are drawn again.
        self._marked, self._ghost_drawn, self._trail_next = 0, (-1, 0), None

    def _touchdowns(self, tracker):
        """The latest run's touchdowns; a new run (or tracker) starts the scene's history afresh."""
        run = self.robot_service.run_snapshot() if self.robot_service is not None else None
        if tracker is not self._tracker:  # connected (again): frames are counted afresh
            self._tracker, self._trail_next = tracker, None
            self._trail_from = 0 if tracker is None else tracker.count()
            self.scene.live_trail.clear()
        if (run is None) != (self._run is None) or (run is not None and run.started != self._run.started):
            self._ghosts, self._marked, self.last_error = {}, 0, None  # a new run
            self._ghost_drawn = (-1, 0)
            self.scene.clear_history()
            self.run_world = LiveWorld.of(run, self.sessions, self.scene.robot)
            # A run's trail starts at its own first frame, however late this view first sees it;
            # with no run, at the frames not drawn yet (or from now on).
            if run is not None and tracker is not None:
                self._trail_from, self._trail_next = run.first_pose, None
            elif self._trail_next is not None:
                self._trail_from = self._trail_next
            elif tracker is not None:
                self._trail_from = tracker.count()
        if self._trail_next is None:
            self._trail_next = self._trail_from
        self._run = run
        return [] if run is None else list(run.touchdowns)

    def _extend_trail(self, tracker) -> None:
        """Draw the robot's frames that arrived since the last frame (the trail keeps the newest)."""
        end = tracker.count()
        # Frames arriving between count() and poses_from() are drawn at the next frame.
        fresh = tracker.poses_from(self._trail_next)[: end - self._trail_next]
        self._trail_next = end
        if fresh:
            self.scene.live_trail.extend(np.array([(p.x, p.y) for p in fresh]))

    def _show_ghost(self, ghost: JumpPlan | None, k: int, t: float) -> None:
        """The model's jump from touchdown ``k`` at time ``t`` [s]: its body, and its trail since
        the touchdown streamed (ChuteScene.live_ghost_trail), afresh at each jump."""
        if ghost is None:
            self.scene.show_ghost(None)
            if self._ghost_drawn != (-1, 0):
                self.scene.live_ghost_trail.clear()
                self._ghost_drawn = (-1, 0)
            return
        self.scene.show_ghost(ghost.clip.pose_at(t))
        jump, drawn = self._ghost_drawn
        if jump != k:
            self.scene.live_ghost_trail.clear()
            drawn = 0
        trail = ghost.clip.body_until(t)[::TRAIL_STRIDE]
        self.scene.live_ghost_trail.extend(trail[drawn:])
        self._ghost_drawn = (k, max(drawn, len(trail)))

    def use_ghost_model(self, name: str) -> None:
        """Predict the ghost with model ``name`` (:func:`frontend.viewer.ghost_models.model_choices`) from now on."""
        model = ghost_model(self.sessions, name)
        with self.lock:
            self.ghost_model, self._ghosts = model, {}
            self._ghost_drawn = (-1, 0)  # the jump under way's trail is drawn again, by this model

    def _ghost(self, touchdowns, k: int) -> JumpPlan | None:
        if k in self._ghosts:
            return self._ghosts[k]
        run, (robot, offsets) = self._run, self.ghost_model
        controls = run.touchdown_controls
        if k >= len(controls):
            return None
        touchdown = touchdowns[k]
        # The leg in flight after touchdown k reaches for the other wall: the one commanded now.
        next_leg = commanded(run, touchdown.wall.other) or controls[k]
        leg, next_leg = (
            realised(offsets, controls[k], touchdown.wall),
            realised(offsets, next_leg, touchdown.wall.other),
        )
        world = self.run_world.world
        try:
            if world is None:
                plan = model_jump(robot, touchdown.state, leg, next_leg, wall=touchdown.wall,
                                  start_time=touchdown.time, start_height=touchdown.body_height)  # fmt: skip
            else:  # the foot on the side it met, at its height: as History's prediction in a world
                plan = world_jump(robot, in_leg_lengths(world, self.run_world.leg_length, robot), touchdown.state,
                                  leg, next_leg, wall=touchdown.wall, start_time=touchdown.time,
                                  foot_height=touchdown.foot_height)  # fmt: skip
        except (ValueError, ArithmeticError):
            plan = None
        self._ghosts[k] = plan
        return plan

    def frame(self, dt: float) -> None:
        service = self.robot_service
        tracker = None if service is None else service.tracker
        touchdowns = self._touchdowns(tracker)
        run_world = self.run_world
        run_world.draw(self.scene)  # sent once a run (again after a mode change)
        # After a mode change, only the markers the ring keeps are drawn again.
        for touchdown in touchdowns[max(self._marked, len(touchdowns) - TOUCHDOWN_MARKERS) :]:
            run_world.mark(self.scene, touchdown)
            previous = self._ghosts.get(touchdown.index - 1)
            if previous is not None and previous.failure is None:
                self.last_error = touchdown.body_height - previous.next_height
        self._marked = len(touchdowns)
        run_world.aim(self.scene, len(touchdowns), self._run is not None and self._run.active)
        if tracker is None:
            return
        self._extend_trail(tracker)
        pose = tracker.latest()
        if pose is None:
            return
        body = PathClip.from_body([pose.time], [pose.x], [pose.y]).pose_at(pose.time)
        self.scene.show(body, None, None, follow=True)
        k = len(touchdowns) - 1
        ghost = bool(touchdowns) and self.gui_ghost.value
        self._show_ghost(self._ghost(touchdowns, k) if ghost else None, k, pose.time)

    def ghost_words(self) -> str:
        """The readout's line of the ghost's jump under way when the model fails it ("" otherwise)."""
        plan = self._ghosts.get(self._marked - 1) if self.gui_ghost.value else None
        if plan is None or plan.failure is None:
            return ""
        where = "in the world" if self.run_world.world is not None else "between the walls"
        failure = plan.failure
        return (f"**Model ghost:** the model's jump from touchdown {self._marked - 1} fails {where}: "
                f"{failure.code} — {failure.message}; drawn up to it  \n")  # fmt: skip

    def readout(self, updates_per_s: float) -> str:
        service = self.robot_service
        if service is None or service.tracker is None:
            return "**No robot connected.** Connect in the control panel's Robot tab; this view follows its tracker."
        status = service.status()
        tracker = status["tracker"]
        latest = tracker["latest"]
        if latest is not None:
            where = f"body at ({latest['x']:.3f}, {latest['y']:.3f}) m"
        else:  # frames may come without the robot's body in them (it is out of view, or another rigid body)
            where = "no frames yet" if not tracker["received"] else "no pose of the robot's body in them yet"
        error = "–" if self.last_error is None else f"{100 * self.last_error:+.1f} cm"
        return (
            f"**Link:** {status['state']} · **tracker:** {tracker['received']} frames, "
            f"{100 * tracker['loss']:.1f}% lost · {where}  \n"
            f"**Touchdowns this run:** {self._marked} · **model's touchdown height error (last jump):** {error}  \n"
            f"{self.ghost_words()}"
            f"{self.run_world.words()}"
            f"{updates_per_s:.0f} updates/s"
        )
