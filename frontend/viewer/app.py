"""The 3D view: a viser server inside the service process, a view per browser, and the frame loop.

:class:`ClimbView` runs viser's web server in viser's own thread on its own port (viser moves to
the next port when the one asked for is busy; :meth:`ClimbView.info` says which) and one loop
thread that draws a frame :data:`FRAME_RATE` times a second for every browser connected. Each
browser has a view of its own (:class:`frontend.viewer.session.ViewerSession`: scene, GUI,
modes, play state), built when it connects and dropped when it leaves, so nothing is drawn or
computed for nobody. The view only reads: it never commands the robot.

The service talks to it through ``backend.services.view.SceneView`` (info, replay a stored run
in one panel's view, share a run as standalone HTML); ``cli.serve`` plugs it in.

Threads: the sessions are kept as an immutable mapping, replaced whole (under a lock) when a
browser comes or goes; the loop and the service read whichever mapping is current.
"""

from __future__ import annotations

import collections
import logging
import threading
import time
import warnings
from dataclasses import dataclass
from types import MappingProxyType

import viser

from backend.services.view import ViewContext, stored_path_key
from backend.settings import LOOPBACK_HOSTS
from frontend.viewer.handshake import refuse_foreign_origins, viewer_of
from frontend.viewer.recordings import Recording, load_recording
from frontend.viewer.scene import place_camera
from frontend.viewer.session import ViewerSession
from frontend.viewer.share import share_html
from sim_core import get_preset

log = logging.getLogger("parkourlab.view")
# Between a browser's websocket closing and viser calling on_client_disconnect, the loop may draw
# one more frame for it; viser warns that those messages go nowhere, which is all they do.
warnings.filterwarnings("ignore", message="Queued a .* on a closed connection", category=UserWarning)
FRAME_RATE = 60.0  # frames drawn per second, per browser (the floor the issue sets is 30)
READOUT_PERIOD = 0.25  # [s] between readout updates: text need not move at frame rate
SHARED_FILES_KEPT = 8  # shared HTML files kept for the next ask (1-4 MB each)
PENDING_REPLAY_S = 60.0  # [s] a replay asked for a panel whose view has not connected yet waits this long
PENDING_REPLAYS_KEPT = 32


@dataclass(frozen=True)
class _Replay:
    """A stored run, read and ready to put on a timeline."""

    run_id: int
    overlay_id: int | None
    recording: Recording
    overlay: Recording | None
    asked: float  # time.monotonic() when it was asked for

    def waiting(self) -> bool:
        """Still to be opened when its view connects (asked no more than PENDING_REPLAY_S ago)."""
        return time.monotonic() - self.asked <= PENDING_REPLAY_S


class ClimbView:
    """The service's 3D view of the chute.

    Args:
        host: interface viser binds (the service's own, localhost unless told otherwise).
        port: viser's port; 0 lets the system pick a free one.
        context: the service's database sessions and robot (for replay and live modes).
        panel_url: where the control panel is, for the link back.
        allowed_hosts: the service's host names: a websocket from a page of any other origin is
            refused (frontend/viewer/handshake.py).
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
        self.panel_url = panel_url
        self.server = viser.ViserServer(host=host, port=port, label="ParkourLab · 3D view", verbose=False)
        refuse_foreign_origins(self.server, allowed_hosts)
        place_camera(self.server)
        self._sessions_lock = threading.Lock()  # orders comings and goings; readers need no lock
        self.sessions: MappingProxyType[int, ViewerSession] = MappingProxyType({})
        self._pending: collections.OrderedDict[str, _Replay] = collections.OrderedDict()
        self._shared: collections.OrderedDict[tuple, str] = collections.OrderedDict()
        self._shared_lock = threading.Lock()
        self.updates_per_s = 0.0
        self.frames = 0
        self._stop = threading.Event()
        self.server.on_client_connect(self._connect)
        self.server.on_client_disconnect(self._disconnect)
        self._thread = threading.Thread(target=self._loop, name="view-loop", daemon=True)
        self._thread.start()

    # Browsers coming and going ------------------------------------------------------------------
    def _connect(self, client: viser.ClientHandle) -> None:
        session = ViewerSession(client, viewer_of(self.server, client), self.context, self.robot,
                                panel_url=self.panel_url, share=self.share_html)  # fmt: skip
        pending = None
        with self._sessions_lock:  # joined and given its pending replay at once (open_run takes it too)
            closing = self._stop.is_set()
            if not closing:
                self.sessions = MappingProxyType({**self.sessions, client.client_id: session})
                pending = self._pending.pop(session.viewer, None) if session.viewer else None
        if closing:
            session.close()
            return
        if pending is not None and pending.waiting():
            session.replay(pending.run_id, pending.overlay_id, pending.recording, pending.overlay)

    def _disconnect(self, client: viser.ClientHandle) -> None:
        # Closed before it leaves the mapping, so a session no longer listed is one that draws and
        # computes nothing (a closed one still listed draws nothing either); the close is outside
        # the lock, as it waits for the session's gait search to stop.
        session = self.sessions.get(client.client_id)
        if session is not None:
            session.close()
        with self._sessions_lock:
            remaining = dict(self.sessions)
            remaining.pop(client.client_id, None)
            self.sessions = MappingProxyType(remaining)

    def sessions_of(self, viewer: str) -> list[ViewerSession]:
        """The connected views of the panel called ``viewer`` (usually one)."""
        return [session for session in self.sessions.values() if session.viewer == viewer]

    # What the service asks --------------------------------------------------------------------
    def info(self, viewer: str | None = None) -> dict:
        """Where the view is and how it runs; with ``viewer``, what that panel's view shows
        (``mode`` and ``run_id`` are None for a panel whose view is not connected)."""
        mode = run_id = None
        if viewer is not None:
            sessions = self.sessions_of(viewer)
            with self._sessions_lock:
                pending = self._pending.get(viewer)
            if pending is not None and not pending.waiting():
                pending = None
            if sessions:
                mode, run_id = sessions[0].mode.name, sessions[0].run_id
            elif pending is not None:
                mode, run_id = "replay", pending.run_id
        return {
            "available": True,
            "port": self.server.get_port(),
            "mode": mode,
            "run_id": run_id,
            "updates_per_s": round(self.updates_per_s, 1),
            "clients": len(self.sessions),
        }

    def open_run(self, viewer: str, run_id: int, overlay_run_id: int | None = None) -> dict:
        """Replay stored run ``run_id`` in the view of the panel called ``viewer`` only
        (NotFound / Conflict, :mod:`backend.errors`, when it cannot be). A view still loading gets it
        when it connects, within :data:`PENDING_REPLAY_S`."""
        sessions = self.context.sessions
        recording = load_recording(sessions, run_id)
        overlay = None if overlay_run_id is None else load_recording(sessions, overlay_run_id)
        replay = _Replay(run_id, overlay_run_id, recording, overlay, time.monotonic())
        with self._sessions_lock:  # against _connect: a view connecting now gets it either way
            targets = self.sessions_of(viewer)
            if not targets:
                self._pending[viewer] = replay
                self._pending.move_to_end(viewer)
                while len(self._pending) > PENDING_REPLAYS_KEPT:
                    self._pending.popitem(last=False)
        for session in targets:
            session.replay(run_id, overlay_run_id, recording, overlay)
        return self.info(viewer)

    def share_html(self, run_id: int, overlay_run_id: int | None = None) -> str:
        """A standalone HTML file that plays stored run ``run_id`` (viser's client with the recorded
        replay inside: it opens offline, from a file, in any browser; frontend/viewer/share.py).
        The last :data:`SHARED_FILES_KEPT` files are kept, by what they were made of."""
        sessions = self.context.sessions
        key = tuple(None if i is None else stored_path_key(sessions, i) for i in (run_id, overlay_run_id))
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
        with self._sessions_lock:
            self._stop.set()
            sessions, self.sessions = self.sessions, MappingProxyType({})
        self._thread.join(timeout=2.0)
        for session in sessions.values():
            session.close()
        self.server.stop()

    # The loop -----------------------------------------------------------------------------------
    def _loop(self) -> None:
        period = 1.0 / FRAME_RATE
        last = next_tick = time.monotonic()
        window_start, window_frames, last_readout = last, 0, 0.0
        failing: set[int] = set()  # sessions whose last frame failed: said once per streak
        while not self._stop.wait(max(0.0, next_tick - time.monotonic())):
            now = time.monotonic()
            dt, last = min(now - last, 0.1), now  # a stall does not make the robot jump ahead
            readout_rate = self.updates_per_s if now - last_readout >= READOUT_PERIOD else None
            if readout_rate is not None:
                last_readout = now
            for client_id, session in self.sessions.items():
                try:
                    session.frame(dt, readout_rate=readout_rate)
                    failing.discard(client_id)
                except Exception:  # one bad frame must not end anyone's view
                    if client_id not in failing:
                        log.exception("3D view: drawing a frame failed")
                    failing.add(client_id)
            failing &= set(self.sessions)
            self.frames += 1
            window_frames += 1
            if now - window_start >= 1.0:
                self.updates_per_s = window_frames / (now - window_start)
                window_start, window_frames = now, 0
            next_tick += period
            if next_tick < now:
                next_tick = now + period
