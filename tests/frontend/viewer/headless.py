"""A browser's connection to the 3D view, without the browser: for tests and scripts/bench_view.py.

It connects as viser's web client does (its subprotocol, the page's Origin, the panel's
``/viewer/ID`` path when it has one), sends one camera message (viser counts a client as
connected from its first), and then receives on a thread of its own, keeping the time and size
of each websocket message: one message is one update of the view (a frame's changes, sent
together). It reads the GUI's labels from the updates (:func:`decode`), so it can change a
control as a person would (:meth:`HeadlessViewer.set_gui`: the Mode dropdown, say).
"""

from __future__ import annotations

import threading
import time

import msgspec
import viser
import zstandard
from websockets.exceptions import ConnectionClosed
from websockets.sync.client import connect

CAMERA = {
    "type": "ViewerCameraMessage",
    "wxyz": (1.0, 0.0, 0.0, 0.0),
    "position": (0.0, -1.25, 0.6),
    "fov": 1.0,
    "near": 0.01,
    "far": 100.0,
    "image_height": 800,
    "image_width": 1280,
    "look_at": (0.0, 0.0, 0.6),
    "up_direction": (0.0, 0.0, 1.0),
}


def decode(update: bytes) -> list[dict]:
    """The messages in one update as viser's web client reads them (viser/infra/_infra.py: the
    lengths of the msgpack part and of its zstd, the zstd, then the arrays, each 8-byte aligned);
    an array stays a placeholder ``{"__binary_index": i, "dtype": ...}`` (not needed here)."""
    size, compressed = int.from_bytes(update[:8], "little"), int.from_bytes(update[8:16], "little")
    inner = zstandard.ZstdDecompressor().decompress(update[16 : 16 + compressed], max_output_size=size)
    return msgspec.msgpack.decode(inner)["messages"]


class HeadlessViewer:
    """One browser's view of the server on ``port`` (``viewer``: the panel's id, or None)."""

    def __init__(
        self, port: int, viewer: str | None = None, *, origin: str = "http://127.0.0.1:8000", path: str | None = None
    ):
        """``path``: the websocket's path as it is (default: the panel's ``/viewer/ID``, or ``/``)."""
        path = path or (f"/viewer/{viewer}" if viewer else "/")
        self.socket = connect(
            f"ws://127.0.0.1:{port}{path}",
            origin=origin,
            subprotocols=[f"viser-v{viser.__version__}"],
            open_timeout=10,
            max_size=None,
        )
        self.socket.send(msgspec.msgpack.encode(CAMERA))
        self.arrivals: list[float] = []  # time.monotonic() of each message
        self.sizes: list[int] = []  # [bytes] of each message
        self.bytes = 0
        self.gui: dict[str, str] = {}  # label -> uuid of each GUI control made so far
        self._thread = threading.Thread(target=self._receive, name="headless-viewer", daemon=True)
        self._thread.start()

    def _receive(self) -> None:
        try:
            for message in self.socket:
                self.arrivals.append(time.monotonic())
                self.sizes.append(len(message))
                self.bytes += len(message)
                self._read_gui(message)
        except ConnectionClosed:
            pass

    def _read_gui(self, update: bytes) -> None:
        for message in decode(update):
            if message["type"].startswith("Gui") and "label" in message.get("props", {}):
                self.gui[message["props"]["label"]] = message["uuid"]

    def set_gui(self, label: str, value, timeout: float = 10.0) -> None:
        """Set the control labelled ``label`` to ``value`` as the browser does when a person
        changes it (viser's ``GuiUpdateMessage``); waits up to ``timeout`` [s] for the control."""
        deadline = time.monotonic() + timeout
        while label not in self.gui:
            if time.monotonic() > deadline:
                raise TimeoutError(f"no GUI control labelled {label!r} arrived")
            time.sleep(0.02)
        update = {"type": "GuiUpdateMessage", "uuid": self.gui[label], "updates": {"value": value}}
        self.socket.send(msgspec.msgpack.encode(update))

    def updates_per_s(self, since: float, until: float | None = None) -> float:
        """Messages per second that arrived between ``since`` and ``until`` (now) [time.monotonic()]."""
        until = time.monotonic() if until is None else until
        return sum(since <= t < until for t in self.arrivals) / (until - since)

    def close(self) -> None:
        self.socket.close()
        self._thread.join(5)

    def __enter__(self) -> HeadlessViewer:
        return self

    def __exit__(self, *_exc) -> None:
        self.close()
