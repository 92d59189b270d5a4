"""Simulate mode: the model climbing in real time with the sliders' controls, holding a height, or
following a plan in a stored world (:mod:`frontend.viewer.modes.plan_follow`).

A slider acts from the next touchdown (:class:`frontend.viewer.simulated_climb.SimulatedClimb`); the
readout names the gait of the controls in use, looked for in the background
(:mod:`frontend.viewer.modes.gait_search`). A controller closes the loop as on the robot: from each
touchdown the chosen law (designed in the background on the sliders' robot, about the gait of
jumping in place at the left leg's angle) sets the next touchdown's leg; the readout shows its command.
"""

from __future__ import annotations

import concurrent.futures
import contextlib
from dataclasses import replace

import viser

from frontend.viewer.modes import Mode
from frontend.viewer.modes.gait_search import CUSTOM, DEFAULT_START, GAIT_PRESETS, find_gait
from frontend.viewer.modes.plan_follow import PlanFollow
from frontend.viewer.motion import TRAIL_STRIDE
from frontend.viewer.scene import ChuteScene
from frontend.viewer.simulated_climb import Controls, SimulatedClimb
from sim_core import FixedPoint, LegControl, PhysicalParams
from sim_core.climb.records import CHUTE_TOP
from sim_core.control.design import law_holding
from sim_core.control.registry import NAMES
from sim_core.model.errors import FixedPointNotFound, ParameterError
from sim_core.model.trajectory import STANCE

OPEN_LOOP = "off"  # the controller dropdown's "the sliders set the legs"


class SimulateMode(Mode):
    """The model climbing in real time with the sliders' controls."""

    name = "simulate"

    def __init__(self, client: viser.ClientHandle, scene: ChuteScene, lock, robot: PhysicalParams, sessions=None):
        super().__init__(client, scene, lock)
        self.base_robot = robot
        gui = client.gui
        (left, right) = next(iter(GAIT_PRESETS.values()))
        with gui.add_folder("Simulate") as self.folder:
            self.gui_preset = gui.add_dropdown("Gait preset", [*GAIT_PRESETS, CUSTOM],
                                               initial_value=next(iter(GAIT_PRESETS)))  # fmt: skip
            self.gui_symmetric = gui.add_checkbox("Symmetric (R = L)", initial_value=True,
                                                  hint="both legs use the left leg's controls")  # fmt: skip
            self.gui_psi0_left = self._ranged_slider("psi0 L [°]", 15.0, 60.0, 0.5, left[0])
            self.gui_zeta0_left = self._ranged_slider("zeta0 L [l0]", 0.80, 0.99, 0.0005, left[1])
            self.gui_psi0_right = self._ranged_slider("psi0 R [°]", 15.0, 60.0, 0.5, right[0], disabled=True)
            self.gui_zeta0_right = self._ranged_slider("zeta0 R [l0]", 0.80, 0.99, 0.0005, right[1], disabled=True)
            self.gui_gravity = self._ranged_slider("gravity [m/s²]", 0.3, 9.81, 0.01, robot.gravity,
                                                   hint="the air table's tilt")  # fmt: skip
            self.gui_damping = self._ranged_slider("damping [N·s/m]", 0.0, 3.0, 0.05, robot.c_zeta,
                                                   hint="leg and pivot")  # fmt: skip
            self.gui_controller = gui.add_dropdown(
                "Controller", (OPEN_LOOP, *NAMES), initial_value=OPEN_LOOP,
                hint="close the loop: from each touchdown the law sets the next leg (the sliders set the first)",
            )  # fmt: skip
            self.gui_target = self._ranged_slider("target [m]", 0.1, CHUTE_TOP, 0.01, 0.55, hint="the height held")
            self.gui_playback = gui.add_button_group("Playback", ("Play", "Pause", "Step jump", "Restart"))
            self.gui_speed = self._ranged_slider("speed [×]", 0.1, 4.0, 0.1, 1.0)
            self.follow = PlanFollow(self, sessions, robot)  # a stored world: plan, follow, play
            self.gui_readout = gui.add_markdown("")
        self._control_handles = (self.gui_psi0_left, self.gui_zeta0_left, self.gui_psi0_right,
                                 self.gui_zeta0_right, self.gui_gravity, self.gui_damping)  # fmt: skip
        for handle in self._control_handles:
            handle.on_update(self._on_control)
        self.speed = 1.0  # [×] the speed in use: the slider's last value in its range
        self.gui_speed.on_update(self._on_speed)
        self.gui_symmetric.on_update(self._on_control)
        self.gui_preset.on_update(self._on_preset)
        self.gui_playback.on_click(self._on_playback)
        self.gui_controller.on_update(self._on_law)
        self.gui_target.on_update(self._on_law)
        self.law_note = "off: the sliders set the legs"
        self._law_generation = 0
        self.playing = True
        self.time = 0.0
        self.input_note: str | None = None  # why what was typed is not used (half-typed, out of range)
        self.speed_note: str | None = None
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
        if self.gui_controller.value != OPEN_LOOP:
            self._design_law()  # the law is the sliders' robot's and leg angle's

    def _on_speed(self, _event) -> None:
        with self.lock:
            self.speed_note = self._out_of_range((self.gui_speed,))
            self.speed = self._usable(self.gui_speed, self.speed)

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
        elif choice == "Restart" and self.follow.active:
            self.follow.restart()
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
        if not self.follow.active:  # a followed plan on show keeps its scene
            self.scene.clear_history()
        self.time, self._shown, self.playing = 0.0, 0, True

    # The closed loop ------------------------------------------------------------------------------
    def _on_law(self, _event) -> None:
        if self._quiet:
            return
        with self.lock:
            note = self._out_of_range((self.gui_target,))
            if note is not None:
                self.law_note = f"not used: {note}"
                return
            self._design_law()

    def _design_law(self) -> None:
        """Design the chosen law in the background (the newest request wins), then restart with it."""
        self._law_generation += 1
        generation, name, controls = self._law_generation, self.gui_controller.value, self.applied
        target_m = float(self.gui_target.value)
        self.law_note = "designing…" if name != OPEN_LOOP else self.law_note

        def design() -> None:
            law, note = None, "off: the sliders set the legs"
            if name != OPEN_LOOP:
                robot = controls.robot
                try:
                    law = law_holding(name, robot.to_model(), target_m / robot.leg_length, controls.left.psi0_deg)
                    note = f"{name} holding {target_m:g} m"
                except (ParameterError, FixedPointNotFound) as error:
                    note = f"{name} cannot be designed here: {error} (the sliders set the legs)"
            with self.lock:
                if generation != self._law_generation:
                    return
                self.law_note = note
                self.climb.set_law(law)
                self._restart()

        with contextlib.suppress(RuntimeError):  # closed: the browser has gone
            self._gait_worker.submit(design)

    def _law_words(self) -> str:
        commands = self.climb.commands
        if self.climb.law is None or not commands:
            return self.law_note
        last = commands[-1]
        clipped = " (clipped to the leg's range)" if last.clipped else ""
        return (f"{self.law_note} · touchdown {last.jump + 1} → psi0 {last.leg.psi0_deg:.2f}°, "
                f"zeta0 {last.leg.zeta0:.4f}{clipped}")  # fmt: skip

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
        self._law_generation += 1
        self._gait_worker.shutdown(wait=False, cancel_futures=True)
        self.follow.close()

    # Per frame ----------------------------------------------------------------------------------
    def frame(self, dt: float) -> None:
        if self.follow.active:
            self.follow.frame(dt, self.speed, self.playing)
            return
        self.scene.set_world(None)
        if self.playing:
            self.time += dt * self.speed
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
        if self.follow.active:
            return f"{self.follow.readout()}  \nt = {self.follow.time:.1f} s · {updates_per_s:.0f} updates/s"
        t = self.time
        pose = self.climb.pose_at(t)
        plans = self.climb.plans
        plan = plans[pose.jump]
        done = [p for p in plans[: pose.jump] if p.failure is None]
        last = f"{100 * done[-1].rise:.2f} cm" if done else "–"
        failed = plan.failure is not None and t >= plan.clip.end
        failure = f"**{plan.failure.code}** at jump {pose.jump + 1}: {plan.failure.message}" if failed else "none"
        robot = self.climb.controls.robot
        notes = [note for note in (self.input_note, self.speed_note) if note]
        typed = f"**Not used:** {'; '.join(notes)} (the climb goes on as before)  \n" if notes else ""
        typed += f"{self.follow.note}  \n" if self.follow.note else ""
        return typed + (
            f"**Jump** {pose.jump + 1} · **height** {pose.y:.3f} m · **climb/jump** {last}  \n"
            f"**Failure:** {failure}  \n"
            f"**Gait of these controls:** {self.gait_note}  \n"
            f"**Controller:** {self._law_words()}  \n"
            f"alpha = {robot.to_model().alpha:.1f} · t = {t:.1f} s · {updates_per_s:.0f} updates/s"
        )
