"""One browser's 3D view: its own scene, GUI, modes and play state.

A :class:`ViewerSession` is built when a browser connects (viser's ``on_client_connect``) and
dropped when it leaves; everything it draws goes through that browser's ``client.scene`` and
``client.gui``, so what one person does — a slider, Pause, a replay, the mode — shows in their
browser only. A new visitor starts fresh, on the first preset. Live mode reads the one robot
through the service's immutable snapshots, so everyone who chooses it sees the same robot.

Threads: viser runs GUI callbacks on its thread pool, and the view's loop draws frames; both take
:attr:`ViewerSession.lock`, which is this session's alone. Once :meth:`close` has run the
session draws and computes nothing more.
"""

from __future__ import annotations

import html
import threading

import viser

from backend.services.view import ViewContext
from frontend.viewer.modes.live import LiveMode
from frontend.viewer.modes.replay import ReplayMode
from frontend.viewer.modes.simulate import SimulateMode
from frontend.viewer.recordings import Recording
from frontend.viewer.scene import ChuteScene
from sim_core import PhysicalParams

MODES = ("simulate", "live", "replay")


class ViewerSession:
    """The view of the browser behind ``client``.

    Args:
        client: viser's handle of the browser's connection.
        viewer: the id of the control panel the browser's view is embedded in (None: opened by
            itself), which History → "3D" names (frontend/viewer/handshake.py).
        context: the service's database sessions and robot.
        robot: the robot the simulate mode starts with (walls, size).
        panel_url: where the control panel is, for the link back.
        share: run id → a standalone HTML file of its replay (the view's, cached for everyone).
    """

    def __init__(
        self,
        client: viser.ClientHandle,
        viewer: str | None,
        context: ViewContext,
        robot: PhysicalParams,
        *,
        panel_url: str,
        share,
    ):
        self.client, self.viewer, self.robot = client, viewer, robot
        self.lock = threading.RLock()
        self.closed = False
        self.scene = ChuteScene(client.scene, robot)
        gui = client.gui
        self.gui_estop, self.gui_estop_said = None, None
        if context.robot_service is not None:
            self.gui_estop, self.gui_estop_said = self._estop_button(gui, context.robot_service)
        # target="_top": the panel embeds this view in a frame, and a plain link loaded a second
        # panel (and a second e-stop) inside it. viser renders a markdown's HTML as it is.
        self._link = f'<a href="{html.escape(panel_url, quote=True)}" target="_top">← Control panel</a>'
        self.gui_header = gui.add_markdown(self._header())
        self.gui_mode = gui.add_dropdown("Mode", MODES, initial_value="simulate")
        self.modes = {
            "simulate": SimulateMode(client, self.scene, self.lock, robot, context.sessions),
            "live": LiveMode(client, self.scene, self.lock, context.robot_service, context.sessions),
            "replay": ReplayMode(client, self.scene, self.lock, context.sessions),
        }
        self.modes["replay"].share = share
        self.mode = self.modes["simulate"]
        self.gui_mode.on_update(lambda _event: self.set_mode(self.gui_mode.value))

    @staticmethod
    def _estop_button(gui, robot_service):
        """The e-stop on the view's own page too (it had none: only the panel's), first in its GUI.
        It presses the service's e-stop (connected or not, bounded, latching) and says the answer."""
        button = gui.add_button("EMERGENCY STOP", color="red", hint="Stops the robot now and latches (needs no token)")
        said = gui.add_markdown("")

        def press(_event) -> None:
            answer = robot_service.estop(by="someone at the 3D view")
            heard = (
                "acknowledged by the robot" if answer.get("acknowledged") else answer.get("reason", "not acknowledged")
            )
            said.content = f"**E-stop sent:** {heard}; latched until a person resets it in the control panel."

        button.on_click(press)
        return button, said

    def _header(self) -> str:
        """The link back to the panel and the chute the scene draws: the walls' distance, or a world's width."""
        return f"{self._link} · {self.scene.chute_words}"

    @property
    def run_id(self) -> int | None:
        """The stored run on this browser's replay timeline, if any."""
        recording = self.modes["replay"].recording
        return None if recording is None else recording.run_id

    def set_mode(self, name: str) -> None:
        with self.lock:
            if name == self.mode.name or self.closed:
                return
            self.mode.deactivate()
            self.mode = self.modes[name]
            self.scene.clear_history()
            self.scene.show_ghost(None)
            self.scene.set_world(None)  # a mode in a world draws it again in its next frame
            if name != "replay":
                self.scene.robot = self.robot
            self.mode.activate()
            if self.gui_mode.value != name:
                self.gui_mode.value = name  # its callback comes back here and returns at once

    def replay(self, run_id: int, overlay_id: int | None, recording: Recording, overlay: Recording | None) -> None:
        """Put stored run ``run_id`` (already read as ``recording``) on this browser's timeline."""
        with self.lock:
            if self.closed:
                return
            self.modes["replay"].show(run_id, overlay_id, recording, overlay)
            self.set_mode("replay")

    def frame(self, dt: float, *, readout_rate: float | None = None) -> None:
        """Draw one frame of the current mode, ``dt`` [s] after the last; with ``readout_rate``
        (the view's frames per second) the readout is written too."""
        with self.lock, self.client.atomic():
            if self.closed:
                return
            self.mode.frame(dt)
            header = self._header()
            if header != self.gui_header.content:  # a mode drew a world, or the walls again
                self.gui_header.content = header
            if readout_rate is not None:
                self.mode.gui_readout.content = self.mode.readout(readout_rate)

    def close(self) -> None:
        """The browser has gone: stop drawing and computing for it (a gait search under way is
        dropped, not finished)."""
        with self.lock:
            self.closed = True
            self.modes["simulate"].close()
