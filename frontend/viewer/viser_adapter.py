"""Every use the view makes of viser's private internals, in one place.

viser (pinned at :data:`WRITTEN_FOR`) has no public hook for two things the view needs:

- the websocket handshake (:mod:`frontend.viewer.handshake`): the per-client connections, to
  read a browser's path and Origin, and the server's event loop, to close one
  (:func:`live_connections`, :func:`websocket_server`, :func:`event_loop`);
- a recording written without handles (:mod:`frontend.viewer.share`): the scene messages a
  ``StateSerializer`` keeps, its binary buffers and clock (:class:`RecordingWriter`), laid out
  and embedded in the client as viser does it (:func:`serialize`, :func:`embed`).

An upgrade of viser can move any of these without notice; tests/frontend/viewer/
test_viser_adapter.py pins the version and checks each against viser's own behaviour, and
:func:`missing` names what is gone. A private attribute read here that is gone raises
:class:`ViserInternalsChanged`, naming it.
"""

from __future__ import annotations

import base64
import html
import re
from pathlib import Path
from typing import Any

import msgspec
import numpy as np
import viser
import zstandard
from viser import _messages
from viser.infra._infra import _append_aligned_buffers

WRITTEN_FOR = "1.1.1"  # the viser version whose internals this module reads
CLIENT_HTML = Path(viser.__file__).parent / "client" / "build" / "index.html"  # viser's single-file client
# The messages a recording writer makes, with their value fields as placeholders.
SET_POSITION = _messages.SetPositionMessage
SET_VISIBILITY = _messages.SetSceneNodeVisibilityMessage
NODE_UPDATE = _messages.SceneNodeUpdateMessage
_PLACEHOLDER_FIELDS = {SET_POSITION: ((0.0, 0.0, 0.0),), SET_VISIBILITY: (True,), NODE_UPDATE: ({},)}


_GONE = object()


class ViserInternalsChanged(RuntimeError):
    """A private part of viser the view relies on is not where this module expects it."""


def _private(owner: object, name: str, kind: type | None = None, *, needed_for: str = "") -> Any:
    """``owner.name``, which must be a ``kind``; ViserInternalsChanged naming it if it is not."""
    value = getattr(owner, name, None)
    if value is None or (kind is not None and not isinstance(value, kind)):
        purpose = f" ({needed_for})" if needed_for else ""
        raise ViserInternalsChanged(
            f"viser {viser.__version__}: no {type(owner).__name__}.{name}{purpose}; "
            f"frontend/viewer/viser_adapter.py was written for viser {WRITTEN_FOR}"
        )
    return value


# The websocket handshake ---------------------------------------------------------------------
def websocket_server(server: viser.ViserServer):
    """The server's websocket server (``on_client_connect`` runs before viser's own handshake)."""
    return _private(server, "_websock_server", needed_for="the websocket server, to check Origins on")


def live_connections(server: viser.ViserServer) -> dict:
    """Client id -> its open websocket connection (``request.path``, ``request.headers``, ``close``)."""
    return _private(websocket_server(server), "_live_connections", dict,
                    needed_for="the per-client connections, to check Origins on")  # fmt: skip


def event_loop(server: viser.ViserServer):
    """The event loop the websockets run on, or None before it has started."""
    websock = websocket_server(server)
    if not hasattr(websock, "_background_event_loop"):
        raise ViserInternalsChanged(f"viser {viser.__version__}: no websocket event loop (written for {WRITTEN_FOR})")
    return websock._background_event_loop


# Recordings ----------------------------------------------------------------------------------
def recorded_messages(serializer) -> list[tuple[float, dict[str, Any]]]:
    """The (time [s], message dict) pairs a ``StateSerializer`` has recorded, in order."""
    return _private(serializer, "_messages", list)


def binary_buffers(serializer) -> list:
    """The arrays a recording's messages point at (``{"__binary_index": i, "dtype": ...}``)."""
    return _private(serializer, "_binary_buffers", list)


class RecordingWriter:
    """Scene messages for a viser ``StateSerializer``, frame by frame: each the dict viser records
    for the same handle assignment or ``add_*`` call (``Message.as_serializable_dict``), without
    the handles' bookkeeping (tests/frontend/viewer/test_viser_adapter.py holds them equal).

    Arrays go into the serializer's binary buffers as viser puts them (a placeholder with the
    buffer's index and dtype); colours, which repeat, share one per colour, as viser's
    de-duplication would make them.
    """

    def __init__(self, serializer, frame_count: int):
        self.serializer = serializer
        self.frames: list[list[dict[str, Any]]] = [[] for _ in range(frame_count)]
        self.frame = 0  # the frame that position(), visible(), update() and make_like() write to
        self._buffers = binary_buffers(serializer)
        self._templates: dict[tuple[type, str], dict[str, Any]] = {}
        self._shared: dict[bytes, int] = {}
        # The nodes made so far, by name: their create messages are the templates of make_like.
        self.made = {message["name"]: message for _t, message in recorded_messages(serializer) if "props" in message}

    def template(self, kind: type, name: str) -> dict[str, Any]:
        """viser's dict of a ``kind`` message (:data:`SET_POSITION`, :data:`SET_VISIBILITY`,
        :data:`NODE_UPDATE`) for node ``name``; its value field is replaced in each use."""
        key = (kind, name)
        template = self._templates.get(key)
        if template is None:
            template = self._templates[key] = kind(name, *_PLACEHOLDER_FIELDS.get(kind, ())).as_serializable_dict()
        return template

    def value(self, value, *, share: bool = False):
        """``value`` as ``as_serializable_dict`` puts it: an array as a placeholder for its binary
        buffer (``_prepare_for_serialization``), a tuple as floats. ``share``: an array equal to one
        written before takes its buffer (for small ones that repeat: colours)."""
        if not isinstance(value, np.ndarray):
            return tuple(float(v) for v in value) if isinstance(value, tuple) else value
        data = np.ascontiguousarray(value)
        key = data.tobytes() if share else None
        index = self._shared.get(key) if share else None
        if index is None:
            index = len(self._buffers)
            self._buffers.append(data.data)
            if share:
                self._shared[key] = index
        return {"__binary_index": index, "dtype": data.dtype.str}

    def position(self, name: str, position) -> None:
        """``handle.position = position`` (three floats [m])."""
        template = self.template(SET_POSITION, name)
        self.frames[self.frame].append({**template, "position": tuple(float(v) for v in position)})

    def visible(self, name: str, visible: bool) -> None:
        """``handle.visible = visible``."""
        template = self.template(SET_VISIBILITY, name)
        self.frames[self.frame].append({**template, "visible": bool(visible)})

    def update(self, name: str, prop: str, value) -> None:
        """``handle.<prop> = value``, cast as the handle casts it (``points`` float32, ``colors`` uint8)."""
        template = self.template(NODE_UPDATE, name)
        self.frames[self.frame].append({**template, "updates": {prop: self.value(value)}})

    def make_like(self, prototype: str, name: str, *, position=None, **props) -> None:
        """A node ``name`` made as node ``prototype`` was (its kind and props, but ``props``), at
        ``position`` (its parent's origin if None), shown: what viser sends for that ``add_*``
        call (create, position, visibility)."""
        template = self.made[prototype]
        same = {prop: dict(value) if isinstance(value, dict) else value for prop, value in template["props"].items()}
        made = {**template, "name": name, "props": {**same, **{k: self.value(v) for k, v in props.items()}}}
        self.frames[self.frame].append(made)
        self.made[name] = made
        if position is not None:
            self.position(name, position)
        self.visible(name, True)

    def positions(self, name: str, writes: np.ndarray, positions: np.ndarray) -> None:
        """``position()`` of node ``name`` at each frame where ``writes``: ``positions[k]`` (K, 3) [m]."""
        template = self.template(SET_POSITION, name)
        frames = np.flatnonzero(writes)
        for k, position in zip(frames.tolist(), positions[frames].tolist(), strict=True):
            self.frames[k].append({**template, "position": tuple(position)})

    def visibles(self, name: str, writes: np.ndarray, visible: np.ndarray) -> None:
        """``visible()`` of node ``name`` at each frame where ``writes``: ``visible[k]``."""
        template = self.template(SET_VISIBILITY, name)
        frames = np.flatnonzero(writes)
        for k, shown in zip(frames.tolist(), visible[frames].tolist(), strict=True):
            self.frames[k].append({**template, "visible": shown})

    def updates(self, name: str, prop: str, writes: np.ndarray, values: np.ndarray, *, share: bool = False) -> None:
        """``update()`` of node ``name``'s ``prop`` at each frame where ``writes``: ``values[k]``."""
        template = self.template(NODE_UPDATE, name)
        for k in np.flatnonzero(writes).tolist():
            self.frames[k].append({**template, "updates": {prop: self.value(values[k], share=share)}})

    def finish(self, times: np.ndarray, *, duration: float) -> None:
        """Into the serializer: frame k's messages at ``times[k]`` [s], the recording ``duration`` s long."""
        recorded_messages(self.serializer).extend(
            [(t, message) for t, frame in zip(times.tolist(), self.frames, strict=True) for message in frame]
        )
        _private(self.serializer, "_time", float)  # the clock viser writes as durationSeconds
        self.serializer._time = duration
        self.frames = []


def serialize(serializer, level: int) -> bytes:
    """The recording as viser's ``StateSerializer.serialize`` lays it out (its "hybrid" format: the
    uncompressed size, then zstd of [msgpack length, msgpack of the messages with placeholders,
    8-byte aligned binary buffers]), compressed at zstd ``level`` (viser's own: 12). Its buffers
    are not de-duplicated again (:class:`RecordingWriter` shares the small ones). Like viser's, it
    ends the recording: the server no longer feeds it, nor keeps it alive."""
    handler = _private(serializer, "_handler")
    with _private(handler, "_record_lock"):
        _private(handler, "_record_handles").remove(serializer)
    buffers = binary_buffers(serializer)
    payload = msgspec.msgpack.encode(
        {
            "durationSeconds": serializer._time,
            "messages": recorded_messages(serializer),
            "viserVersion": viser.__version__,
            "binaryBufferLengths": tuple(buffer.nbytes for buffer in buffers),
        }
    )
    parts: list = [len(payload).to_bytes(8, "little"), payload]
    _append_aligned_buffers(parts, buffers, 8 + len(payload))
    size = sum(memoryview(part).nbytes for part in parts)
    compressor = zstandard.ZstdCompressor(level=level, threads=-1).compressobj(size=size)
    out = [size.to_bytes(8, "little")]
    out.extend(compressor.compress(part) for part in parts)
    out.append(compressor.flush())
    return b"".join(out)


# A shared file's caption: the run's description over the scene, top left (the file opens from
# disk, under no policy: an inline style is fine there).
CAPTION = (
    '<div id="parkourlab-caption" style="position:fixed;top:.5rem;left:.5rem;z-index:1000;max-width:40rem;'
    "padding:.3rem .6rem;border-radius:4px;background:#fffd;color:#23303c;font:13px/1.35 system-ui,sans-serif;"
    'pointer-events:none">{text}</div>'
)


def embed(recording: bytes, *, title: str | None = None, description: str | None = None) -> str:
    """viser's single-file client with ``recording`` inside, as ``StateSerializer.as_html`` makes it;
    with ``title`` and ``description`` (text, escaped here) in place of the client's own ("Viser",
    "Viser client"), the description also shown over the scene."""
    client = CLIENT_HTML.read_text()
    if title is not None:
        client = re.sub(r"<title>[^<]*</title>", lambda _: f"<title>{html.escape(title)}</title>", client, count=1)
    if description is not None:
        meta = f'<meta name="description" content="{html.escape(description, quote=True)}" />'
        client = re.sub(r'<meta name="description"[^>]*>', lambda _: meta, client, count=1)
        body = client.index("<body>") + len("<body>")
        client = client[:body] + CAPTION.format(text=html.escape(description)) + client[body:]
    data = base64.b64encode(recording).decode("ascii")
    script = f'<script>window.__VISER_EMBED_DATA__="{data}";window.__VISER_EMBED_CONFIG__={{darkMode:false}};</script>'
    head_end = client.index("</head>")
    return client[:head_end] + script + client[head_end:]


def slider_marks(handle) -> tuple[tuple[float, str | None], ...] | None:
    """A slider's marks as (value, label) pairs (viser keeps them as its private ``_marks`` prop)."""
    marks = getattr(handle, "_marks")  # noqa: B009 - a prop viser names private
    return None if marks is None else tuple((mark.value, mark.label) for mark in marks)


def set_slider_marks(handle, marks: tuple[tuple[float, str], ...]) -> None:
    """Move a slider's marks (``add_slider(marks=...)`` sets them once; there is no public setter):
    the change goes to the browser as any prop's does."""
    handle._marks = tuple(_messages.GuiSliderMark(value=float(value), label=label) for value, label in marks)


def missing(server: viser.ViserServer) -> list[str]:
    """What this module reads of viser that ``server`` (a running one) or its scene serializer
    lacks, by name; empty when everything is where it expects. Takes a recording from the server
    (and ends it)."""
    gone = []
    if "_marks" not in getattr(_messages.GuiSliderProps, "__annotations__", {}) or not hasattr(
        _messages, "GuiSliderMark"
    ):
        gone.append("GuiSliderProps._marks (GuiSliderMark)")
    for name, read in (
        ("ViserServer._websock_server", lambda: websocket_server(server)),
        ("WebsockServer._live_connections", lambda: live_connections(server)),
        ("WebsockServer._background_event_loop", lambda: event_loop(server)),
    ):
        try:
            read()
        except ViserInternalsChanged:
            gone.append(name)
    serializer = server.get_scene_serializer()
    for owner, name, kind in (
        (serializer, "_messages", list),
        (serializer, "_binary_buffers", list),
        (serializer, "_time", float),
        (serializer, "_handler", object),
        (getattr(serializer, "_handler", None), "_record_lock", object),
        (getattr(serializer, "_handler", None), "_record_handles", list),
    ):
        value = getattr(owner, name, _GONE)
        if value is _GONE or not isinstance(value, kind):
            gone.append(f"{type(owner).__name__}.{name}")
    client = CLIENT_HTML.read_text() if CLIENT_HTML.is_file() else ""
    if not all(part in client for part in ("</head>", "<body>", "<title>", '<meta name="description"')):
        gone.append(f"the single-file client at {CLIENT_HTML} (its head, body, title and description)")
    with_handler = getattr(serializer, "_handler", None)
    if with_handler is not None and serializer in getattr(with_handler, "_record_handles", ()):
        with_handler._record_handles.remove(serializer)
    return gone
