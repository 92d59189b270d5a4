"""Replay mode: a stored run on a timeline, with another run as a ghost if asked, and the body's
height plotted beside it. Runs are read through :func:`frontend.viewer.recordings.load_recording`;
a frame is drawn by :func:`frontend.viewer.modes.painter.show_frame`, as the shared file draws it.
"""

from __future__ import annotations

import contextlib

import numpy as np
import viser

from backend.errors import Conflict, NotFound
from frontend.viewer.modes import Mode
from frontend.viewer.modes.painter import show_frame
from frontend.viewer.recordings import Recording, load_recording
from frontend.viewer.scene import ChuteScene

MAX_RUN_ID = 2**31 - 1  # the store's largest id (backend.schemas.MAX_ID)
TIME_STEP = 0.01  # [s] the timeline slider's step
PLOT_SAMPLES = 400  # the replay's height plot: samples over the run (the dot moves sample by sample)
CURSOR_PERIOD = 0.1  # [s] the plot's dot moves at most this often


class ReplayMode(Mode):
    """A stored run on a timeline, with another run as a ghost if asked."""

    name = "replay"

    def __init__(self, client: viser.ClientHandle, scene: ChuteScene, lock, sessions):
        super().__init__(client, scene, lock)
        self.sessions = sessions
        gui = client.gui
        with gui.add_folder("Replay", visible=False) as self.folder:
            self.gui_run = self._ranged_number("Run id", 1, low=1, high=MAX_RUN_ID)
            self.gui_overlay = self._ranged_number("Overlay run id (0: none)", 0, low=0, high=MAX_RUN_ID)
            self.gui_load = gui.add_button("Load")
            self.gui_time = self._ranged_slider("Time [s]", 0.0, 1.0, TIME_STEP, 0.0)
            self.gui_playback = gui.add_button_group("Playback", ("Play", "Pause", "Start"))
            self.gui_speed = self._ranged_slider("speed [×]", 0.1, 4.0, 0.1, 1.0)
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
        self.end = 0.0  # [s] the timeline's end: the longer run's
        self.speed = 1.0  # [×] the speed in use: the slider's last value in its range
        self.input_note: str | None = None  # why a typed time or speed is not used
        self.share = None  # set by the view: run id -> standalone HTML
        self.gui_load.on_click(self._on_load)
        self.gui_time.on_update(self._on_scrub)
        self.gui_speed.on_update(self._on_speed)
        self.gui_playback.on_click(self._on_playback)
        self.gui_share.on_click(self._on_share)

    def _on_load(self, _event) -> None:
        problem = self._out_of_range((self.gui_run, self.gui_overlay))
        if problem is not None:  # nothing loaded: the run on the timeline stays
            self.message = f"**Cannot replay:** {problem}" + (
                f"; still showing {self.recording.label}" if self.recording else ""
            )
            return
        with contextlib.suppress(NotFound, Conflict):  # the readout says why
            self.load(int(self.gui_run.value), int(self.gui_overlay.value) or None)

    def load(self, run_id: int, overlay_id: int | None = None) -> None:
        """Show stored run ``run_id`` (and ``overlay_id`` as a ghost) from its start, paused.
        Raises NotFound or Conflict (nothing to replay), and says so in the readout."""
        try:
            recording = load_recording(self.sessions, run_id)
            overlay = None if overlay_id is None else load_recording(self.sessions, overlay_id)
        except (NotFound, Conflict) as error:
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
        self.end = round(max(duration, TIME_STEP), 2)
        with self._quietly():
            self.gui_run.value = run_id
            self.gui_overlay.value = overlay_id or 0
            self._set_range(self.gui_time, 0.0, self.end, TIME_STEP)
            self.gui_time.value = 0.0
        self.time, self.playing, self._marked = 0.0, False, (0, 0)
        self.input_note = None
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
            self.input_note = self._out_of_range((self.gui_time, self.gui_speed))
            if self._problem(self.gui_time) is not None:
                return  # a time not on the timeline: the replay stays where it is
            self.time = float(self.gui_time.value)
            self._marked = (0, 0)
            self.scene.clear_history()

    def _on_speed(self, _event) -> None:
        with self.lock:
            self.input_note = self._out_of_range((self.gui_time, self.gui_speed))
            self.speed = self._usable(self.gui_speed, self.speed)

    def _on_playback(self, event) -> None:
        with self.lock:
            self.playback(event.target.value)

    def playback(self, choice: str) -> None:
        """One of the Playback buttons: Play, Pause, Start."""
        if choice == "Play" and self.recording is not None:
            if self.time >= self.end:
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
            self.time = min(self.time + dt * self.speed, self.end)
            self.playing = self.time < self.end
            with self._quietly():
                self.gui_time.value = round(self.time, 2)
        self._marked = show_frame(self.scene, recording, self.overlay, self.time, self._marked)
        self._move_cursor(dt)

    def readout(self, updates_per_s: float) -> str:
        if self.recording is None:
            return self.message or "Pick a run and press Load."
        pose = self.recording.clip.pose_at(self.time)
        typed = f"  \n**Not used:** {self.input_note}" if self.input_note else ""
        return f"{self.message}{typed}  \nt = {self.time:.2f} s · height {pose.y:.3f} m · {updates_per_s:.0f} updates/s"
