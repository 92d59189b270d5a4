"""The 3D view: a viser server inside the service process, its GUI, and the frame loop.

:class:`ClimbView` runs viser's web server in viser's own thread on its own port (viser moves to
the next port when the one asked for is busy; :meth:`ClimbView.info` says which) and one loop
thread that draws a frame of the current mode :data:`FRAME_RATE` times a second. The scene and
GUI are shared by everyone who opens the view, like a monitor on the lab wall. The view only
reads: it never commands the robot.

The service talks to it through ``backend.services.view.SceneView`` (info, replay a stored run,
share a run as standalone HTML); ``cli.serve`` plugs it in.
"""

from __future__ import annotations

import collections
import html
import logging
import threading
import time

import viser

from backend.services.view import ViewContext
from backend.settings import LOOPBACK_HOSTS
from frontend.viewer.modes import LiveMode, ReplayMode, SimulateMode
from frontend.viewer.origins import refuse_foreign_origins
from frontend.viewer.recordings import load_recording, recording_key
from frontend.viewer.scene import ChuteScene, place_camera
from frontend.viewer.share import share_html
from sim_core import get_preset

log = logging.getLogger("parkourlab.view")
FRAME_RATE = 60.0  # frames drawn per second (the floor the issue sets is 30)
READOUT_PERIOD = 0.25  # [s] between readout updates: text need not move at frame rate
SHARED_FILES_KEPT = 8  # shared HTML files kept for the next ask (1-4 MB each)


class ClimbView:
    """The service's 3D view of the chute.

    Args:
        host: interface viser binds (the service's own, localhost unless told otherwise).
        port: viser's port; 0 lets the system pick a free one.
        context: the service's database sessions and robot (for replay and live modes).
        panel_url: where the control panel is, for the link back.
        allowed_hosts: the service's host names: a websocket from a page of any other origin is
            refused (frontend/viewer/origins.py).
    """

    def __init__(
        self,
        context: ViewContext,
        *,
        host: str = "127.0.0.1",
        port: int = 0,
        panel_url: str = "/",
        allowed_hosts: tuple[str, ...] = LOOPBACK_HOSTS,
    ):
        self.context = context
        self.robot = get_preset("paper")
        self.allowed_hosts = allowed_hosts
        self.server = viser.ViserServer(host=host, port=port, label="ParkourLab · 3D view", verbose=False)
        refuse_foreign_origins(self.server, allowed_hosts)
        place_camera(self.server)
        self.scene = ChuteScene(self.server.scene, self.robot)
        gui = self.server.gui
        # target="_top": the panel embeds this view in a frame, and a plain link loaded a second
        # panel (and a second e-stop) inside it. viser renders a markdown's HTML as it is.
        link = f'<a href="{html.escape(panel_url, quote=True)}" target="_top">← Control panel</a>'
        gui.add_markdown(f"{link} · walls {self.robot.wall_distance:.2f} m apart")
        self.gui_mode = gui.add_dropdown("Mode", ("simulate", "live", "replay"), initial_value="simulate")
        self.lock = threading.RLock()  # the loop and GUI callbacks take turns on the modes
        self.modes = {
            "simulate": SimulateMode(self.server, self.scene, self.lock, self.robot),
            "live": LiveMode(self.server, self.scene, self.lock, context.robot_service),
            "replay": ReplayMode(self.server, self.scene, self.lock, context.sessions),
        }
        self.modes["replay"].share = self.share_html
        self.mode = self.modes["simulate"]
        self.gui_mode.on_update(lambda _event: self.set_mode(self.gui_mode.value))
        self._shared: collections.OrderedDict[tuple, str] = collections.OrderedDict()
        self._shared_lock = threading.Lock()
        self.updates_per_s = 0.0
        self.frames = 0
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._loop, name="view-loop", daemon=True)
        self._thread.start()

    # What the service asks --------------------------------------------------------------------
    def info(self) -> dict:
        return {
            "available": True,
            "port": self.server.get_port(),
            "mode": self.mode.name,
            "run_id": None if self.modes["replay"].recording is None else self.modes["replay"].recording.run_id,
            "updates_per_s": round(self.updates_per_s, 1),
            "clients": len(self.server.get_clients()),
        }

    def open_run(self, run_id: int, overlay_run_id: int | None = None) -> dict:
        """Replay stored run ``run_id`` (records.NotFound / records.Conflict when it cannot be)."""
        self.modes["replay"].load(run_id, overlay_run_id)
        self.set_mode("replay")
        return self.info()

    def share_html(self, run_id: int, overlay_run_id: int | None = None) -> str:
        """A standalone HTML file that plays stored run ``run_id`` (viser's client with the recorded
        replay inside: it opens offline, from a file, in any browser; frontend/viewer/share.py).
        The last :data:`SHARED_FILES_KEPT` files are kept, by what they were made of."""
        sessions = self.context.sessions
        key = tuple(None if i is None else recording_key(sessions, i) for i in (run_id, overlay_run_id))
        with self._shared_lock:
            if key in self._shared:
                self._shared.move_to_end(key)
                return self._shared[key]
        recording = load_recording(sessions, run_id)
        overlay = None if overlay_run_id is None else load_recording(sessions, overlay_run_id)
        html = share_html(recording, overlay, allowed_hosts=self.allowed_hosts)
        with self._shared_lock:
            self._shared[key] = html
            while len(self._shared) > SHARED_FILES_KEPT:
                self._shared.popitem(last=False)
        return html

    def close(self) -> None:
        self._stop.set()
        self._thread.join(timeout=2.0)
        self.server.stop()

    # Modes and the loop -----------------------------------------------------------------------
    def set_mode(self, name: str) -> None:
        with self.lock:
            if name == self.mode.name:
                return
            self.mode.deactivate()
            self.mode = self.modes[name]
            self.scene.clear_history()
            self.scene.show_ghost(None)
            if name != "replay":
                self.scene.robot = self.robot
            self.mode.activate()
            if self.gui_mode.value != name:
                self.gui_mode.value = name  # its callback comes back here and returns at once

    def _loop(self) -> None:
        period = 1.0 / FRAME_RATE
        last = next_tick = time.monotonic()
        window_start, window_frames, last_readout = last, 0, 0.0
        failing = False
        while not self._stop.wait(max(0.0, next_tick - time.monotonic())):
            now = time.monotonic()
            dt, last = min(now - last, 0.1), now  # a stall does not make the robot jump ahead
            try:
                with self.lock, self.server.atomic():
                    self.mode.frame(dt)
                    if now - last_readout >= READOUT_PERIOD:
                        self.mode.gui_readout.content = self.mode.readout(self.updates_per_s)
                        last_readout = now
                failing = False
            except Exception:  # one bad frame must not end the view; say it once per streak
                if not failing:
                    log.exception("3D view: drawing a frame failed")
                failing = True
            self.frames += 1
            window_frames += 1
            if now - window_start >= 1.0:
                self.updates_per_s = window_frames / (now - window_start)
                window_start, window_frames = now, 0
            next_tick += period
            if next_tick < now:
                next_tick = now + period
