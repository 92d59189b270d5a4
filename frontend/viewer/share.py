"""A stored run's replay as one standalone HTML file ("Share this run", ``GET /api/v1/runs/{id}/share.html``).

The file is viser's single-file client with a recording embedded (viser's format: timed scene
messages, msgpack and zstd, base64 in the page), which plays offline, from disk, looping, with a
time slider. The recording is the chute as :class:`ChuteScene` builds it, then a frame every
1/:data:`EXPORT_RATE` s of the run (at most :data:`MAX_EXPORT_SECONDS`): the scene the replay
mode shows at that instant (:func:`frontend.viewer.modes.painter.show_frame`): the robot and its
legs, its trail, touchdown markers and finished jumps' trails, the ghost.

Made fast (issue 14: a 10-minute run took 20-26 s when each frame was drawn on a live scene
through viser's handles, ~0.15 ms a property and ~0.5 ms a node, then compressed at zstd level 12):

- every frame's pose, legs, colours and trail come from the recording's arrays at once (numpy),
  and only what differs from the frame before is written;
- the writes go into a viser ``StateSerializer`` as the message dicts viser records for the same
  handle assignments (:class:`frontend.viewer.viser_adapter.RecordingWriter`, held equal to
  viser's by tests/frontend/viewer/test_viser_adapter.py), not through handles;
- the nodes are made by :class:`ChuteScene` on a private viser server (port 0, for the length of
  the call), so the scene is the live view's; those made during the run (touchdown markers, past
  trails, ruler sections and labels) are written like the ones it made;
- :func:`frontend.viewer.viser_adapter.serialize` lays the recording out as viser's
  ``StateSerializer.serialize`` does, at zstd level 3 instead of 12.
"""

from __future__ import annotations

import contextlib
import gc
from collections.abc import Iterable

import numpy as np
import viser

from backend.settings import LOOPBACK_HOSTS
from frontend.viewer.geometry import bow_legs, energy_colors, polyline_segments, to_scene
from frontend.viewer.handshake import refuse_foreign_origins
from frontend.viewer.motion import TRAIL_STRIDE
from frontend.viewer.node_rings import NodeRing
from frontend.viewer.recordings import Recording
from frontend.viewer.scene import FOLLOW_MARGIN, ChuteScene, place_camera
from frontend.viewer.viser_adapter import NODE_UPDATE, RecordingWriter, embed, serialize
from sim_core.model.trajectory import STANCE
from sim_core.model.walls import Wall

EXPORT_RATE = 30.0  # frames per second of a shared replay (the browser paints at its own rate)
MAX_EXPORT_SECONDS = 600.0
LEG_TOLERANCE = 1e-6  # [m] a leg that moved less than this since the last frame is not written again
ZSTD_LEVEL = 3  # viser's files use 12 (0.5 s for a 10-minute run, for 10% less), its live link 1


def share_html(
    recording: Recording, overlay: Recording | None = None, *, allowed_hosts: Iterable[str] = LOOPBACK_HOSTS
) -> str:
    """The standalone HTML file that replays ``recording`` (with ``overlay`` as the ghost)."""
    with _no_gc_pauses():
        return _recorded_html(recording, overlay, tuple(allowed_hosts))


def page_text(recording: Recording, overlay: Recording | None = None) -> dict[str, str]:
    """The file's title (what a browser's tab and a mail's attachment list show) and description
    (its summary, shown over the scene too): the run's, as text; :func:`embed` escapes them."""
    title = f"ParkourLab {recording.label}" + (f", ghost {overlay.label}" if overlay else "")
    description = recording.description or f"ParkourLab {recording.label}."
    if overlay is not None:
        description += f" Ghost: {overlay.description or overlay.label}"
    return {"title": title, "description": description}


def frame_times(recording: Recording, overlay: Recording | None = None) -> np.ndarray:
    """[s] the instants the file shows: every 1/EXPORT_RATE s from 0 past the end of the longer run."""
    end = min(max(recording.duration, overlay.duration if overlay else 0.0), MAX_EXPORT_SECONDS)
    return np.arange(0.0, end + 1.0 / EXPORT_RATE, 1.0 / EXPORT_RATE)


def _recorded_html(recording: Recording, overlay: Recording | None, allowed_hosts: tuple[str, ...]) -> str:
    server = viser.ViserServer(host="127.0.0.1", port=0, label=recording.label, verbose=False)
    try:
        refuse_foreign_origins(server, allowed_hosts)
        place_camera(server)
        scene = ChuteScene(server.scene, recording.robot)
        scene.set_world(recording.world, recording.robot.leg_length, recording.world_mu)
        for ring in (scene.touchdown_markers, scene.jump_trails, scene.ghost_jump_trails):
            ring.node(0)  # made by viser, hidden: the template of the ring's other nodes
        serializer = server.get_scene_serializer()
        times = frame_times(recording, overlay)
        out = RecordingWriter(serializer, len(times))
        record(scene, out, recording, overlay, times)
        out.finish(times, duration=len(times) / EXPORT_RATE)
        return embed(serialize(serializer, ZSTD_LEVEL), **page_text(recording, overlay))
    finally:
        server.stop()


@contextlib.contextmanager
def _no_gc_pauses():
    """The cyclic garbage collector off while a recording is built: it makes ~100,000 small dicts
    that live until it is encoded, and each collection walks them all (a third of the time of a
    10-minute file). Back on once they are freed (they make no cycles), unless it was off before."""
    was_enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if was_enabled:
            gc.enable()


def _writes(values: np.ndarray, initial, updated: np.ndarray | None = None, tolerance: float = 0.0) -> np.ndarray:
    """Which frames write a node property: frame k sets ``values[k]`` where ``updated[k]`` (the
    others leave what the node shows), the node starts at ``initial`` (``np.inf``: a placeholder,
    any value differs); a frame writes when its value differs from what the node shows by more
    than ``tolerance``."""
    count = len(values)
    flat = np.asarray(values, dtype=float).reshape(count, -1)
    start = np.broadcast_to(np.asarray(initial, dtype=float).reshape(1, -1), (1, flat.shape[1]))
    updated = np.ones(count, dtype=bool) if updated is None else np.asarray(updated, dtype=bool)
    last = np.maximum.accumulate(np.where(updated, np.arange(count), -1))
    shown = np.where((last >= 0)[:, None], flat[np.maximum(last, 0)], start)
    before = np.vstack([start, shown[:-1]])
    with np.errstate(invalid="ignore"):  # inf - inf: still the placeholder, not written
        return updated & (np.abs(shown - before).max(axis=1) > tolerance)


class _Trail:
    """A trail node over the frames: ``Recording.trail_span``'s strided samples ``[lo, hi)``,
    written where they change and are two points or more (as ``ChuteScene.show`` and
    ``show_ghost`` draw them)."""

    def __init__(self, recording: Recording, times: np.ndarray, node: str):
        self.clip, self.node = recording.clip, node
        self.lo, hi = recording.trail_span(times)
        self.count = (hi - self.lo + TRAIL_STRIDE - 1) // TRAIL_STRIDE
        self.drawn = self.count >= 2
        self.writes = _writes(np.column_stack([self.lo, self.count]), (-1, 0), self.drawn)
        # ``lo`` only grows: frames that share it are consecutive, and each one's trail is the
        # start of the longest of them, made once.
        starts = np.flatnonzero(np.r_[True, self.lo[1:] != self.lo[:-1]])
        self.longest = np.repeat(np.maximum.reduceat(self.count, starts), np.diff(np.r_[starts, len(self.lo)]))

    def write(self, out: RecordingWriter) -> None:
        template = out.template(NODE_UPDATE, self.node)
        since, segments = -1, None
        for k in np.flatnonzero(self.writes).tolist():
            lo, count = int(self.lo[k]), int(self.count[k])
            if lo != since:
                stop = lo + TRAIL_STRIDE * int(self.longest[k])
                path = np.column_stack([self.clip.x[lo:stop:TRAIL_STRIDE], self.clip.y[lo:stop:TRAIL_STRIDE]])
                since, segments = lo, polyline_segments(path).astype(np.float32)
            out.frames[k].append({**template, "updates": {"points": out.value(segments[: count - 1])}})


def _leg_frames(recording: Recording, frames, wall: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The leg node reaching for ``wall`` over the frames, as ``ChuteScene.show`` draws it: where
    the pose's leg reaches for ``wall``, that leg; elsewhere the idle leg, held at its touchdown
    controls. Returns (points (K, n, 2, 3) float32, colours (K, 3) uint8, drawn (K,)): frames where
    it is not drawn (legs unknown) leave it as it was, hidden."""
    robot, l0 = recording.robot, recording.robot.leg_length
    chords = np.column_stack([frames.foot_x - frames.x, frames.foot_y - frames.y])
    zeta = frames.zeta.copy()
    idle = frames.leg_wall != wall
    if recording.legs is not None:
        idle_leg = recording.idle_leg(Wall(-wall))  # this node is the idle leg when the pose's reaches for -wall
        length = idle_leg.zeta0 * l0
        chords[idle] = (wall * length * np.cos(idle_leg.psi0), -length * np.sin(idle_leg.psi0))
        zeta[idle] = length
    drawn = np.isfinite(frames.zeta) & (~idle | (recording.legs is not None))
    chords[~drawn] = 0.0
    points = polyline_segments(bow_legs(chords, l0)).astype(np.float32)
    colors = energy_colors(np.where(drawn, zeta, l0), robot)
    return points, colors, drawn


def _show_item(out: RecordingWriter, ring: NodeRing, k: int, **props) -> None:
    """Item ``k`` of ``ring`` shown with ``props``, as ``NodeRing.show_next``; its node made like
    node 0 the first time."""
    name = f"{ring.prefix}{k % ring.size}"
    if name not in out.made:
        out.make_like(f"{ring.prefix}0", name, **props)
        return
    for prop, value in props.items():
        if prop == "position":
            out.position(name, value)
        else:
            out.update(name, prop, value)
    out.visible(name, True)


def _history(out: RecordingWriter, scene: ChuteScene, recording: Recording, times: np.ndarray, ghost: bool) -> None:
    """Touchdown markers and finished jumps' trails (``ghost``: the ghost's jump trails), each at
    the frame where its touchdown is passed, as ``show_frame`` adds them."""
    marked = np.r_[0, recording.touchdowns_until(times)]
    trails = scene.ghost_jump_trails if ghost else scene.jump_trails
    shown = 0
    for k in np.flatnonzero(np.diff(marked)).tolist():
        out.frame = k
        for i in range(int(marked[k]), int(marked[k + 1])):
            if not ghost:
                marker = scene.touchdown_position(*recording.touchdown_marker(i))
                _show_item(out, scene.touchdown_markers, i, position=marker)
            path = recording.jump_trail(i) if i > 0 else ()
            if len(path) >= 2:
                _show_item(out, trails, shown, points=polyline_segments(path).astype(np.float32))
                shown += 1


def record(
    scene: ChuteScene, out: RecordingWriter, recording: Recording, overlay: Recording | None, times: np.ndarray
) -> None:
    """Write the replay of ``recording`` (``overlay`` as the ghost) at ``times`` into ``out``, on
    ``scene``: fresh from ``ChuteScene(...)``, its rings' node 0 made (the templates of the others),
    in ``out``'s serializer already. What each frame sets is computed for all frames at once; a
    node's property is written where it differs from what the node shows."""
    frames = recording.clip.sampled_at(times)
    count = len(times)
    known = np.isfinite(frames.zeta)

    # The walls and the ruler grow ahead of the robot (ChuteScene.reach).
    tops = scene.top_for(frames.y)
    for k in np.flatnonzero(tops > np.maximum.accumulate(np.r_[scene.top, tops[:-1]])).tolist():
        out.frame = k
        growth = scene.growth(float(frames.y[k]))
        for wall, position in zip(scene.walls, growth.wall_positions, strict=True):
            out.update(wall.name, "dimensions", growth.wall_dimensions)
            out.position(wall.name, position)
        out.make_like("/chute/ruler", growth.section, points=growth.segments.astype(np.float32))
        for name, text, position in growth.labels:
            out.make_like("/chute/ruler/label_0", name, text=text, position=position)
        scene.grew(growth)
    _history(out, scene, recording, times, ghost=False)

    body = to_scene(frames.x, frames.y)  # ChuteScene.show
    out.positions(scene.body.name, _writes(body, scene.body.position), body)
    for wall, node in scene.legs.items():
        points, colors, drawn = _leg_frames(recording, frames, wall)
        out.updates(node.name, "points", _writes(points, np.inf, drawn, LEG_TOLERANCE), points)
        segment_colors = np.broadcast_to(colors[:, None, None, :], points.shape)
        out.updates(node.name, "colors", _writes(colors, np.inf, drawn), segment_colors, share=True)
        out.visibles(node.name, _writes(drawn, node.visible), drawn)
    foot = to_scene(frames.foot_x, frames.foot_y)
    foot_visible = known & (frames.phase == STANCE)
    out.positions(scene.foot.name, _writes(foot, scene.foot.position, foot_visible), foot)  # where it is seen
    out.visibles(scene.foot.name, _writes(foot_visible, scene.foot.visible), foot_visible)
    _Trail(recording, times, scene.trail.name).write(out)
    root = np.zeros((count, 3))
    root[:, 2] = -np.maximum(frames.y - FOLLOW_MARGIN, 0.0)  # follow: the chute slides down
    out.positions(scene.root.name, _writes(root, scene.root.position), root)

    if overlay is None:
        return
    ghost = overlay.clip.sampled_at(times)  # ChuteScene.show_ghost
    out.frame = 0
    out.visible(scene.ghost.name, True)
    ghost_body = to_scene(ghost.x, ghost.y)
    out.positions(scene.ghost.name, _writes(ghost_body, scene.ghost.position), ghost_body)
    trail = _Trail(overlay, times, scene.ghost_trail.name)
    trail.write(out)
    out.visibles(scene.ghost_trail.name, _writes(trail.drawn, scene.ghost_trail.visible), trail.drawn)
    _history(out, scene, overlay, times, ghost=True)
