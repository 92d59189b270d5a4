"""The 3D view's three modes, each a GUI folder plus a ``frame(dt)`` the view's loop calls.

Every browser has its own three (:mod:`frontend.viewer.session`): the GUI and scene they draw
are that browser's (``client.gui``, ``client.scene``), so one person's sliders, play state and
replay are theirs alone.

- :class:`SimulateMode` — the model climbs in real time; sliders act from the next touchdown;
- :class:`LiveMode` — the body follows the robot's tracker stream, the model's prediction of
  the jump under way beside it as a ghost;
- :class:`ReplayMode` — a stored run on a timeline, optionally with a second run as a ghost.

GUI handles are named ``gui_*``. Setting a handle's value from Python runs its callbacks
(viser calls them synchronously), so code that sets values does it inside ``self._quietly()``
and the callbacks ignore what happens there: no feedback loops.
"""

from __future__ import annotations

import concurrent.futures
import contextlib
import math
from dataclasses import replace

import numpy as np
import viser

from backend.robot.messages import Leg
from backend.services import records
from frontend.viewer.ghost_models import BASE, ghost_model, model_choices, realised
from frontend.viewer.motion import STANCE, TRAIL_STRIDE, Controls, JumpPlan, PathClip, SimulatedClimb, model_jump
from frontend.viewer.recordings import Recording, load_recording
from frontend.viewer.scene import TOUCHDOWN_MARKERS, ChuteScene
from sim_core import ControlSchedule, FixedPoint, LegControl, PhysicalParams
from sim_core.errors import NoGaitFound
from sim_core.fixed_points import gait_of
from sim_core.presets import PAPER_GAITS, START_GUESS


def _preset_label(name: str, pairs: tuple[tuple[float, float], ...]) -> str:
    """``"period 2 · 30°/30° · 0.87/0.90"``: zeta0 with at least two decimals."""
    angles = "/".join(f"{psi0:g}°" for psi0, _ in pairs)
    lengths = "/".join(f"{zeta0:.2f}" if round(zeta0, 2) == zeta0 else f"{zeta0:g}" for _, zeta0 in pairs)
    return f"{name} · {angles} · {lengths}"


# The paper's gaits (Fig. 7, sim_core.presets.PAPER_GAITS): psi0 [deg] and zeta0 [l0] of the
# left and right legs; a one-pair gait is both legs'.
GAIT_PRESETS = {_preset_label(name, pairs): (pairs[0], pairs[-1]) for name, pairs in PAPER_GAITS.items()}
CUSTOM = "custom"
DEFAULT_START = START_GUESS  # section state when the controls have no stable gait to start on
PLOT_SAMPLES = 400  # the replay's height plot: samples over the run (the dot moves sample by sample)
CURSOR_PERIOD = 0.1  # [s] the plot's dot moves at most this often
GAIT_SEARCH_PERIOD = 4  # the readout looks for gaits of period 1, 2 and 4 (the paper's)


def _range_words(low, high) -> str:
    if low is not None and high is not None:
        return f"{low:g} to {high:g}"
    return f"at least {low:g}" if low is not None else f"at most {high:g}"


class _Mode:
    """``lock`` is the browser's session's: the loop holds it for each frame, callbacks for each change."""

    def __init__(self, client: viser.ClientHandle, scene: ChuteScene, lock):
        self.client, self.scene, self.lock = client, scene, lock
        self._quiet = False

    @contextlib.contextmanager
    def _quietly(self):
        self._quiet, before = True, self._quiet
        try:
            yield
        finally:
            self._quiet = before

    def activate(self) -> None:
        self.folder.visible = True

    @staticmethod
    def _out_of_range(handles) -> str | None:
        """Why the values in ``handles`` (sliders, number boxes) cannot be used yet, or None. A
        number box sends what is typed as it is typed: "0" on the way to "0.9", or nothing."""
        problems = []
        for handle in handles:
            value, low, high = handle.value, handle.min, handle.max
            usable = isinstance(value, int | float) and math.isfinite(value)
            if not usable or (low is not None and value < low) or (high is not None and value > high):
                problems.append(f"{handle.label} must be {_range_words(low, high)}")
        return "; ".join(problems) or None

    @staticmethod
    def _clamped(handle, default: float) -> float:
        """A slider's value held to its range (``default`` where it holds no number)."""
        value = handle.value
        if not isinstance(value, int | float) or not math.isfinite(value):
            return default
        return float(min(max(value, handle.min), handle.max))

    def deactivate(self) -> None:
        self.folder.visible = False


class SimulateMode(_Mode):
    """The model climbing in real time with the sliders' controls."""

    name = "simulate"

    def __init__(self, client: viser.ClientHandle, scene: ChuteScene, lock, robot: PhysicalParams):
        super().__init__(client, scene, lock)
        self.base_robot = robot
        gui = client.gui
        (left, right) = next(iter(GAIT_PRESETS.values()))
        with gui.add_folder("Simulate") as self.folder:
            self.gui_preset = gui.add_dropdown(
                "Gait preset", [*GAIT_PRESETS, CUSTOM], initial_value=next(iter(GAIT_PRESETS))
            )
            self.gui_symmetric = gui.add_checkbox(
                "Symmetric (R = L)", initial_value=True, hint="both legs use the left leg's controls"
            )
            self.gui_psi0_left = gui.add_slider("psi0 L [°]", 15.0, 60.0, 0.5, left[0])
            self.gui_zeta0_left = gui.add_slider("zeta0 L [l0]", 0.80, 0.99, 0.0005, left[1])
            self.gui_psi0_right = gui.add_slider("psi0 R [°]", 15.0, 60.0, 0.5, right[0], disabled=True)
            self.gui_zeta0_right = gui.add_slider("zeta0 R [l0]", 0.80, 0.99, 0.0005, right[1], disabled=True)
            self.gui_gravity = gui.add_slider(
                "gravity [m/s²]", 0.3, 9.81, 0.01, robot.gravity, hint="the air table's tilt"
            )
            self.gui_damping = gui.add_slider("damping [N·s/m]", 0.0, 3.0, 0.05, robot.c_zeta, hint="leg and pivot")
            self.gui_playback = gui.add_button_group("Playback", ("Play", "Pause", "Step jump", "Restart"))
            self.gui_speed = gui.add_slider("speed [×]", 0.1, 4.0, 0.1, 1.0)
            self.gui_readout = gui.add_markdown("")
        self._control_handles = (self.gui_psi0_left, self.gui_zeta0_left, self.gui_psi0_right,
                                 self.gui_zeta0_right, self.gui_gravity, self.gui_damping)  # fmt: skip
        for handle in self._control_handles:
            handle.on_update(self._on_control)
        self.gui_symmetric.on_update(self._on_control)
        self.gui_preset.on_update(self._on_preset)
        self.gui_playback.on_click(self._on_playback)
        self.playing = True
        self.time = 0.0
        self.input_note: str | None = None  # why what was typed is not in use (half-typed, out of range)
        self.applied = self.controls()  # the controls in use: the sliders' last usable values
        self.gait: FixedPoint | None = None
        self.gait_note = "searching…"
        self._gait_worker = concurrent.futures.ThreadPoolExecutor(max_workers=1, thread_name_prefix="gait")
        self._gait_generation = 0
        self.climb = SimulatedClimb(self.applied, DEFAULT_START)
        self._shown = 0  # jumps whose touchdown marker and trail are drawn
        self._find_gait(restart=True)

    # Controls -----------------------------------------------------------------------------------
    def controls(self) -> Controls:
        left = LegControl.from_degrees(self.gui_psi0_left.value, self.gui_zeta0_left.value)
        if self.gui_symmetric.value:
            right = left
        else:
            right = LegControl.from_degrees(self.gui_psi0_right.value, self.gui_zeta0_right.value)
        damping = float(self.gui_damping.value)
        robot = replace(self.base_robot, gravity=float(self.gui_gravity.value), c_zeta=damping, c_psi=damping)
        return Controls(left, right, robot)

    def set_preset(self, name: str) -> None:
        """Put the sliders on one of :data:`GAIT_PRESETS` and restart there."""
        (psi_l, zeta_l), (psi_r, zeta_r) = GAIT_PRESETS[name]
        with self._quietly():
            self.gui_preset.value = name
            self.gui_symmetric.value = (psi_l, zeta_l) == (psi_r, zeta_r)
            self.gui_psi0_left.value, self.gui_zeta0_left.value = psi_l, zeta_l
            self.gui_psi0_right.value, self.gui_zeta0_right.value = psi_r, zeta_r
            self.gui_gravity.value, self.gui_damping.value = self.base_robot.gravity, self.base_robot.c_zeta
        self._controls_changed(restart=True)

    def _on_preset(self, _event) -> None:
        if not self._quiet and self.gui_preset.value != CUSTOM:
            with self.lock:
                self.set_preset(self.gui_preset.value)

    def _on_control(self, _event) -> None:
        if self._quiet:
            return
        with self.lock:
            self.input_note = self._out_of_range(self._control_handles)
        if self.input_note is not None:
            return  # the climb goes on with the controls in use until the value is whole
        with self.lock, self._quietly():
            self.gui_preset.value = CUSTOM
            if self.gui_symmetric.value:
                self.gui_psi0_right.value, self.gui_zeta0_right.value = (
                    self.gui_psi0_left.value,
                    self.gui_zeta0_left.value,
                )
        with self.lock:
            self._controls_changed(restart=False)

    def _controls_changed(self, *, restart: bool) -> None:
        self.gui_psi0_right.disabled = self.gui_zeta0_right.disabled = self.gui_symmetric.value
        self.input_note = None
        self.applied = self.controls()
        self.climb.set_controls(self.applied)
        self._find_gait(restart=restart)

    def _on_playback(self, event) -> None:
        with self.lock:
            self.playback(event.target.value)

    def playback(self, choice: str) -> None:
        """One of the Playback buttons: Play, Pause, Step jump, Restart."""
        if choice == "Play":
            self.playing = True
        elif choice == "Pause":
            self.playing = False
        elif choice == "Step jump":
            self.playing = False
            self.time = self.climb.next_touchdown_time(self.time)
        elif choice == "Restart":
            self.restart()

    def restart(self) -> None:
        """Back to the floor, on the current controls' stable gait if there is one."""
        with self.lock:
            self._restart()

    def _restart(self) -> None:
        gait = self.gait
        start = tuple(gait.state) if gait is not None and gait.stable else DEFAULT_START
        self.climb.set_controls(self.applied)
        self.climb.reset(start)
        self.scene.clear_history()
        self.time, self._shown, self.playing = 0.0, 0, True

    # The fixed-point readout --------------------------------------------------------------------
    def _find_gait(self, *, restart: bool) -> None:
        """Look for the gait of the current controls in the background (the newest request wins)."""
        self._gait_generation += 1
        generation, controls = self._gait_generation, self.applied
        self.gait_note = "searching…"
        guess = self.climb.current.state

        def search() -> None:
            gait, note = find_gait(controls, guess)
            with self.lock:  # the session's: a browser that left has bumped the generation under it
                if generation != self._gait_generation:
                    return
                self.gait, self.gait_note = gait, note
                if restart:
                    self._restart()

        with contextlib.suppress(RuntimeError):  # closed: the browser has gone
            self._gait_worker.submit(search)

    def close(self) -> None:
        """Compute nothing more: a search under way is not waited for and its answer is dropped."""
        self._gait_generation += 1
        self._gait_worker.shutdown(wait=False, cancel_futures=True)

    # Per frame ----------------------------------------------------------------------------------
    def frame(self, dt: float) -> None:
        if self.playing:
            self.time += dt * self._clamped(self.gui_speed, 1.0)
        pose = self.climb.pose_at(self.time)
        plans = self.climb.plans
        for k in range(self._shown, pose.jump + 1):
            self.scene.add_touchdown(plans[k].wall, float(plans[k].clip.foot_y[0]))
            if k > 0:
                previous = plans[k - 1].clip
                self.scene.add_jump_trail(previous.body_until(previous.end)[::TRAIL_STRIDE])
        self._shown = max(self._shown, pose.jump + 1)
        plan = plans[pose.jump]
        idle = plan.next_leg if pose.phase == STANCE else plan.leg
        trail = plan.clip.body_until(self.time)[::TRAIL_STRIDE]
        self.scene.show(pose, idle, trail, follow=True)
        if plan.failure is not None and self.time >= plan.clip.end:
            self.playing = False

    def readout(self, updates_per_s: float) -> str:
        t = self.time
        pose = self.climb.pose_at(t)
        plans = self.climb.plans
        plan = plans[pose.jump]
        done = [p for p in plans[: pose.jump] if p.failure is None]
        last = f"{100 * done[-1].rise:.2f} cm" if done else "–"
        failed = plan.failure is not None and t >= plan.clip.end
        failure = f"**{plan.failure.code}** at jump {pose.jump + 1}: {plan.failure.message}" if failed else "none"
        robot = self.climb.controls.robot
        typed = f"**Not in use yet:** {self.input_note}  \n" if self.input_note else ""
        return typed + (
            f"**Jump** {pose.jump + 1} · **height** {pose.y:.3f} m · **climb/jump** {last}  \n"
            f"**Failure:** {failure}  \n"
            f"**Gait of these controls:** {self.gait_note}  \n"
            f"alpha = {robot.to_model().alpha:.1f} · t = {t:.1f} s · {updates_per_s:.0f} updates/s"
        )


def find_gait(controls: Controls, guess) -> tuple[FixedPoint | None, str]:
    """The gait (period 1, 2 or 4) of ``controls`` near ``guess``, or the best a grid search finds,
    and a line describing it. Runs in the view's background worker (plain, non-parallel kernels)."""
    model = controls.robot.to_model()
    legs = (controls.left,) if controls.left == controls.right else (controls.left, controls.right)
    schedule = ControlSchedule.of(*legs)
    try:
        gait = gait_of(model, schedule, GAIT_SEARCH_PERIOD, guess, grid=(4, 4), prefer_stable=True)
    except NoGaitFound:
        return None, "none found (a grid search of period 1, 2 and 4 found no gait)"
    climb_cm = 100 * gait.climb_per_period / gait.period * controls.robot.leg_length
    stability = "stable" if gait.stable else "**unstable**"
    state = ", ".join(f"{v:.3f}" for v in gait.state)
    return gait, (
        f"period {gait.period}, {stability}, max|λ| = {gait.max_abs_eigenvalue:.3f}, "
        f"{gait.motion} {climb_cm:+.2f} cm/jump, fixed point ({state})"
    )


class LiveMode(_Mode):
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
        next_leg = run.command_for(Leg.of(touchdown.wall.other)) or controls[k]
        leg, next_leg = (
            realised(offsets, controls[k], touchdown.wall),
            realised(offsets, next_leg, touchdown.wall.other),
        )
        try:
            plan = model_jump(robot, touchdown.state, leg, next_leg, wall=touchdown.wall,
                              start_time=touchdown.time, start_height=touchdown.body_height)  # fmt: skip
        except (ValueError, ArithmeticError):
            plan = None
        self._ghosts[k] = plan
        return plan

    def frame(self, dt: float) -> None:
        service = self.robot_service
        tracker = None if service is None else service.tracker
        touchdowns = self._touchdowns(tracker)
        # After a mode change, only the markers the ring keeps are drawn again.
        for touchdown in touchdowns[max(self._marked, len(touchdowns) - TOUCHDOWN_MARKERS) :]:
            self.scene.add_touchdown(touchdown.wall, touchdown.foot_height)
            previous = self._ghosts.get(touchdown.index - 1)
            if previous is not None and previous.failure is None:
                self.last_error = touchdown.body_height - previous.next_height
        self._marked = len(touchdowns)
        if tracker is None:
            return
        self._extend_trail(tracker)
        pose = tracker.latest()
        if pose is None:
            return
        body = PathClip.from_body([pose.time], [pose.x], [pose.y]).pose_at(pose.time)
        self.scene.show(body, None, None, follow=True)
        k = len(touchdowns) - 1
        self._show_ghost(self._ghost(touchdowns, k) if touchdowns and self.gui_ghost.value else None, k, pose.time)

    def readout(self, updates_per_s: float) -> str:
        service = self.robot_service
        if service is None or service.tracker is None:
            return "**No robot connected.** Connect in the control panel's Robot tab; this view follows its tracker."
        status = service.status()
        tracker = status["tracker"]
        latest = tracker["latest"]
        where = "no frames yet" if latest is None else f"body at ({latest['x']:.3f}, {latest['y']:.3f}) m"
        error = "–" if self.last_error is None else f"{100 * self.last_error:+.1f} cm"
        return (
            f"**Link:** {status['state']} · **tracker:** {tracker['received']} frames, "
            f"{100 * tracker['loss']:.1f}% lost · {where}  \n"
            f"**Touchdowns this run:** {self._marked} · **model's touchdown height error (last jump):** {error}  \n"
            f"{updates_per_s:.0f} updates/s"
        )


class ReplayMode(_Mode):
    """A stored run on a timeline, with another run as a ghost if asked."""

    name = "replay"

    def __init__(self, client: viser.ClientHandle, scene: ChuteScene, lock, sessions):
        super().__init__(client, scene, lock)
        self.sessions = sessions
        gui = client.gui
        with gui.add_folder("Replay", visible=False) as self.folder:
            self.gui_run = gui.add_number("Run id", 1, min=1, step=1)
            self.gui_overlay = gui.add_number("Overlay run id (0: none)", 0, min=0, step=1)
            self.gui_load = gui.add_button("Load")
            self.gui_time = gui.add_slider("Time [s]", 0.0, 1.0, 0.01, 0.0)
            self.gui_playback = gui.add_button_group("Playback", ("Play", "Pause", "Start"))
            self.gui_speed = gui.add_slider("speed [×]", 0.1, 4.0, 0.1, 1.0)
            self.gui_share = gui.add_button("Share this run (HTML)", hint="a standalone file that plays this replay")
            self.gui_readout = gui.add_markdown("Pick a run and press Load (History → “3D” does it for you).")
        self.plot = None
        self._curves: tuple[np.ndarray, ...] = ()  # the plot's time grid [s] and heights [m]
        self._cursor_at: int | None = None  # the grid sample the plot's dot is on
        self._cursor_wait = 0.0  # [s] until the dot may move again
        self.recording: Recording | None = None
        self.overlay: Recording | None = None
        self.playing = False
        self.time = 0.0
        self._marked = (0, 0)  # touchdowns of the run and of the ghost drawn so far
        self.message = ""
        self.share = None  # set by the view: run id -> standalone HTML
        self.gui_load.on_click(self._on_load)
        self.gui_time.on_update(self._on_scrub)
        self.gui_playback.on_click(self._on_playback)
        self.gui_share.on_click(self._on_share)

    def _on_load(self, _event) -> None:
        problem = self._out_of_range((self.gui_run, self.gui_overlay))
        if problem is not None:
            self.message = f"**Cannot replay:** {problem}"
            return
        with contextlib.suppress(records.NotFound, records.Conflict):  # the readout says why
            self.load(int(self.gui_run.value), int(self.gui_overlay.value) or None)

    def load(self, run_id: int, overlay_id: int | None = None) -> None:
        """Show stored run ``run_id`` (and ``overlay_id`` as a ghost) from its start, paused.
        Raises records.NotFound or records.Conflict (nothing to replay), and says so in the readout."""
        try:
            recording = load_recording(self.sessions, run_id)
            overlay = None if overlay_id is None else load_recording(self.sessions, overlay_id)
        except (records.NotFound, records.Conflict) as error:
            self.message = f"**Cannot replay:** {error}"
            self.recording = None
            raise
        self.show(run_id, overlay_id, recording, overlay)

    def show(self, run_id, overlay_id, recording: Recording, overlay: Recording | None) -> None:
        """Put ``recording`` (stored run ``run_id``) on the timeline, ``overlay`` as its ghost."""
        with self.lock:
            self._show(run_id, overlay_id, recording, overlay)

    def _show(self, run_id, overlay_id, recording: Recording, overlay: Recording | None) -> None:
        self.recording, self.overlay = recording, overlay
        duration = max(recording.duration, overlay.duration if overlay else 0.0)
        with self._quietly():
            self.gui_run.value = run_id
            self.gui_overlay.value = overlay_id or 0
            self.gui_time.max = round(max(duration, 0.01), 2)
            self.gui_time.value = 0.0
        self.time, self.playing, self._marked = 0.0, False, (0, 0)
        self.scene.robot = recording.robot
        self.scene.clear_history()
        self._plot(recording, overlay)
        self.message = f"**{recording.label}**" + (f" · ghost: {overlay.label}" if overlay else "")

    def _plot(self, recording: Recording, overlay: Recording | None) -> None:
        """The body's height over the run, with a dot at the replay's time (:meth:`_move_cursor`)."""
        if self.plot is not None:
            self.plot.remove()
        clips = [recording.clip] + ([overlay.clip] if overlay else [])
        end = max(clip.end for clip in clips)
        grid = np.linspace(0.0, end, PLOT_SAMPLES)
        self._curves = (grid, *(np.interp(grid, clip.time, clip.y, right=np.nan) for clip in clips))
        series = [{"label": "t [s]"}, {"label": f"run {recording.run_id} height [m]", "stroke": "#23303c", "width": 2}]
        if overlay:
            series.append({"label": f"run {overlay.run_id} [m]", "stroke": "#50aae6", "width": 2})
        series.append({"label": "now", "stroke": "#e8590c", "width": 0,
                       "points": {"show": True, "size": 10, "fill": "#e8590c"}})  # fmt: skip
        self._cursor_at = None
        with self.folder:
            self.plot = self.client.gui.add_uplot(
                (*self._curves, self._cursor(0.0)),
                tuple(series),
                title="Body height",
                aspect=1.6,
                order=self.gui_readout.order - 0.5,
                # Seconds of the run, not dates; heights on a fixed range: uPlot's own ranging
                # turns NaN (the dot's series, a ghost that ends sooner) into a NaN scale and a
                # blank plot once the data is sent again.
                scales={"x": {"time": False}, "y": {"range": self._height_range()}},
                axes=({"label": "time [s]"}, {"label": "height [m]"}),
            )

    def _height_range(self) -> tuple[float, float]:
        """[m] the plot's height axis: the curves' lowest to highest, with a margin."""
        heights = np.concatenate(self._curves[1:])
        heights = heights[np.isfinite(heights)]
        low, high = (float(heights.min()), float(heights.max())) if heights.size else (0.0, 1.0)
        margin = max(0.05 * (high - low), 0.01)
        return (round(low - margin, 3), round(high + margin, 3))

    def _sample_at(self, t: float) -> int:
        """The plot's sample at ``t`` [s] (the first at or after it, the last past the end)."""
        grid = self._curves[0]
        return int(np.clip(np.searchsorted(grid, t), 0, grid.size - 1))

    def _cursor(self, t: float) -> np.ndarray:
        """The "now" series: the run's height at the sample nearest ``t`` [s], nothing elsewhere."""
        height, k = self._curves[1], self._sample_at(t)
        now = np.full(height.size, np.nan)
        now[k] = height[k]
        return now

    def _move_cursor(self, dt: float) -> None:
        """Move the plot's dot with the body when it has moved a sample, at most every
        CURSOR_PERIOD (the whole plot goes to the browser each time)."""
        self._cursor_wait -= dt
        if self.plot is None or self._cursor_wait > 0.0:
            return
        k = self._sample_at(self.time)
        if k != self._cursor_at:
            self._cursor_at, self._cursor_wait = k, CURSOR_PERIOD
            self.plot.data = (*self._curves, self._cursor(self.time))

    def _on_scrub(self, _event) -> None:
        if self._quiet or self.recording is None:
            return
        with self.lock:
            self.time = self._clamped(self.gui_time, self.time)
            self._marked = (0, 0)
            self.scene.clear_history()

    def _on_playback(self, event) -> None:
        with self.lock:
            self.playback(event.target.value)

    def playback(self, choice: str) -> None:
        """One of the Playback buttons: Play, Pause, Start."""
        if choice == "Play" and self.recording is not None:
            if self.time >= self.gui_time.max:
                self.time = 0.0
            self.playing = True
        elif choice == "Pause":
            self.playing = False
        elif choice == "Start":
            self.time, self._marked, self.playing = 0.0, (0, 0), False
            self.scene.clear_history()

    def _on_share(self, event) -> None:
        if self.recording is None or event.client is None or self.share is None:
            return
        html = self.share(self.recording.run_id)
        event.client.send_file_download(f"parkourlab-run-{self.recording.run_id}.html", html.encode())

    def frame(self, dt: float) -> None:
        recording = self.recording
        if recording is None:
            return
        if self.playing:
            self.time = min(self.time + dt * self._clamped(self.gui_speed, 1.0), float(self.gui_time.max))
            self.playing = self.time < self.gui_time.max
            with self._quietly():
                self.gui_time.value = round(self.time, 2)
        self._marked = show_frame(self.scene, recording, self.overlay, self.time, self._marked)
        self._move_cursor(dt)

    def readout(self, updates_per_s: float) -> str:
        if self.recording is None:
            return self.message or "Pick a run and press Load."
        pose = self.recording.clip.pose_at(self.time)
        return f"{self.message}  \nt = {self.time:.2f} s · height {pose.y:.3f} m · {updates_per_s:.0f} updates/s"


def show_frame(
    scene: ChuteScene, recording: Recording, overlay: Recording | None, t: float, marked: tuple[int, int]
) -> tuple[int, int]:
    """Draw ``recording`` at time ``t`` (and ``overlay`` as the ghost). ``marked``: the touchdowns
    of each drawn so far (their markers and finished jumps' trails); returns them at ``t``.

    The shared file (frontend/viewer/share.py) writes the same scene frame by frame from the
    recording's arrays: what a frame shows is defined by :class:`Recording`'s ``touchdowns_until``,
    ``trail`` and ``jump_trail`` for both."""
    shown, ghost_shown = marked
    now = int(recording.touchdowns_until(t))
    for k in range(shown, now):
        _time, wall, foot_height = recording.touchdowns[k]
        scene.add_touchdown(int(wall), float(foot_height))
        if k > 0:
            scene.add_jump_trail(recording.jump_trail(k))
    pose = recording.clip.pose_at(t)
    scene.show(pose, recording.idle_leg(pose.leg_wall), recording.trail(t), follow=True)
    if overlay is None:
        scene.show_ghost(None)
        return now, 0
    ghost_now = int(overlay.touchdowns_until(t))
    for k in range(max(ghost_shown, 1), ghost_now):
        scene.add_ghost_jump_trail(overlay.jump_trail(k))
    scene.show_ghost(overlay.clip.pose_at(t), overlay.trail(t))
    return now, ghost_now
