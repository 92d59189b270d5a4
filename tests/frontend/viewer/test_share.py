"""The shared file (frontend/viewer/share.py): viser's client with the run's replay recorded inside.

The file is decoded here as viser's client decodes it (base64, zstd, msgpack, aligned binary
buffers) and its messages are applied to a model of the client's scene tree, frame by frame. The
scene it shows is compared with the one the live replay draws (``show_frame`` on a ChuteScene,
through viser's handles, recorded by viser's own serializer) at every frame. Speed is measured by
scripts/bench_share.py, not here.
"""

from __future__ import annotations

import base64
import dataclasses
import re

import msgspec
import numpy as np
import pytest
import viser
import zstandard

from backend.schemas import LegIn, RunCreate, StateIn
from backend.services import runs as run_service
from backend.store.database import make_engine, migrate, session_factory, sqlite_url
from backend.store.models import Run
from backend.store.trajectory_blob import pack_trajectory
from frontend.viewer import share
from frontend.viewer.geometry import to_scene
from frontend.viewer.modes.painter import show_frame
from frontend.viewer.recordings import load_recording
from frontend.viewer.scene import TOUCHDOWN_MARKERS, TRAIL_JUMPS, ChuteScene

CONTROLS = [LegIn(psi0_deg=30, zeta0=0.87), LegIn(psi0_deg=30, zeta0=0.9)]
START = StateIn(xdot=-0.8, ydot=-0.15)
JUMPS = 70  # more touchdowns than the markers' ring holds, more jumps than the trails' ring


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """A migrated store with a sim run and its path, the same run without (simulated again when
    replayed), and a robot run: tracker frames (120 Hz, body only) along the first's path."""
    engine = make_engine(sqlite_url(tmp_path_factory.mktemp("share")))
    migrate(engine)
    sessions = session_factory(engine)
    with sessions() as session:
        body = {"controls": CONTROLS, "start": START, "jumps": JUMPS}
        stored = run_service.create_run(session, RunCreate(**body, trajectory_rate=60)).id
        again = run_service.create_run(session, RunCreate(**body)).id
    path = load_recording(sessions, stored)
    t = np.arange(0.0, path.duration, 1 / 120)
    body = path.clip.sampled_at(t)
    frames = {"time": 50.0 + t, "x": body.x, "y": body.y}
    touchdowns = [{"time": 50.0 + time, "wall": int(wall), "foot_height": h} for time, wall, h in path.touchdowns]
    with sessions() as session:
        run = Run(kind="robot", status="done", code_version="test", model={}, controls=[[30, 0.87], [30, 0.9]],
                  start_state=[0, 0], jumps=JUMPS, alpha=1, psi0_deg=30, zeta0=0.87, jumps_completed=JUMPS, climb=0,
                  results={"touchdowns": touchdowns}, trajectory=pack_trajectory(frames))  # fmt: skip
        session.add(run)
        session.commit()
        robot = run.id
    ids = {"sim": stored, "again": again, "robot": robot}
    yield {name: load_recording(sessions, run_id) for name, run_id in ids.items()}
    engine.dispose()


# The file, decoded as the client decodes it ------------------------------------------------------


def decode(html: str) -> dict:
    """The recording in a shared file: ``durationSeconds``, ``viserVersion``, ``messages`` (time,
    message) with each binary placeholder replaced by its array."""
    data = re.search(r'window\.__VISER_EMBED_DATA__="([^"]*)"', html).group(1)
    return decode_recording(base64.b64decode(data))


def decode_recording(raw: bytes) -> dict:
    size = int.from_bytes(raw[:8], "little")
    inner = zstandard.ZstdDecompressor().decompress(raw[8:], max_output_size=size)
    length = int.from_bytes(inner[:8], "little")
    recording = msgspec.msgpack.decode(inner[8 : 8 + length])
    offset, buffers = 8 + length, []
    for nbytes in recording["binaryBufferLengths"]:
        offset += (8 - offset % 8) % 8
        buffers.append(inner[offset : offset + nbytes])
        offset += nbytes

    def resolve(value):
        if isinstance(value, dict):
            if "__binary_index" in value:
                return np.frombuffer(buffers[value["__binary_index"]], dtype=value["dtype"])
            return {key: resolve(item) for key, item in value.items()}
        if isinstance(value, list):
            return [resolve(item) for item in value]
        return value

    recording["messages"] = [(t, resolve(message)) for t, message in recording["messages"]]
    return recording


class SceneTree:
    """The client's scene as the messages leave it: per node its kind, props, position, visibility."""

    def __init__(self):
        self.nodes: dict[str, dict] = {}
        self.changed: set[str] = set()  # names a message touched since the caller last emptied it

    def apply(self, message: dict) -> None:
        kind, name = message["type"], message.get("name")
        self.changed.add(name)
        if "props" in message:
            node = self.nodes.setdefault(name, {"position": (0.0, 0.0, 0.0), "visible": True})
            node["kind"], node["props"] = kind, dict(message["props"])
        elif kind == "SetPositionMessage":
            self.nodes[name]["position"] = tuple(message["position"])
        elif kind == "SetSceneNodeVisibilityMessage":
            self.nodes[name]["visible"] = message["visible"]
        elif kind == "SceneNodeUpdateMessage":
            self.nodes[name]["props"].update(message["updates"])
        elif kind == "RemoveSceneNodeMessage":
            for other in [n for n in self.nodes if n == name or n.startswith(name + "/")]:
                del self.nodes[other]

    def shown(self) -> dict[str, dict]:
        """The nodes drawn: visible, and every parent visible."""

        def drawn(name: str) -> bool:
            while name:
                if name in self.nodes and not self.nodes[name]["visible"]:
                    return False
                name = name.rsplit("/", 1)[0]
            return True

        return {name: node for name, node in self.nodes.items() if "kind" in node and drawn(name)}


def scenes_by_frame(recording: dict, times: np.ndarray):
    """The scene after each frame's messages (those at or before its time), and the names those
    messages touched; the nodes are changed by the next frame, so use them before taking it."""
    tree, messages, i = SceneTree(), recording["messages"], 0
    for t in times:
        while i < len(messages) and messages[i][0] <= t + 1e-9:
            tree.apply(messages[i][1])
            i += 1
        yield tree.shown(), tree.changed
        tree.changed = set()


def live_replay(recording, overlay, times) -> dict:
    """The replay mode's scene, frame by frame: show_frame on a ChuteScene through viser's
    handles, recorded by viser's own serializer."""
    server = viser.ViserServer(host="127.0.0.1", port=0, verbose=False)
    try:
        scene = ChuteScene(server.scene, recording.robot)
        serializer = server.get_scene_serializer()
        marked = (0, 0)
        for t in times:
            marked = show_frame(scene, recording, overlay, float(t), marked)
            serializer.insert_sleep(1 / share.EXPORT_RATE)
        return decode_recording(serializer.serialize())
    finally:
        server.stop()


def assert_same_node(name, shared, live, t):
    assert shared["kind"] == live["kind"], name
    assert np.allclose(shared["position"], live["position"], atol=1e-9), (name, t)
    assert shared["props"].keys() == live["props"].keys(), name
    for prop, value in live["props"].items():
        if isinstance(value, np.ndarray):
            written = shared["props"][prop]
            assert (written.dtype, written.shape) == (value.dtype, value.shape), (name, prop, t)
            assert np.array_equal(written, value) or np.allclose(written, value, atol=1e-5), (name, prop, t)
        else:
            assert shared["props"][prop] == value, (name, prop, t)


# Tests -------------------------------------------------------------------------------------------


@pytest.mark.parametrize(("run", "ghost"), [("sim", None), ("again", "sim"), ("robot", None)])
def test_the_file_shows_the_scene_the_replay_shows_at_every_frame(runs, run, ghost):
    recording, overlay = runs[run], runs.get(ghost)
    times = share.frame_times(recording, overlay)
    shared = decode(share.share_html(recording, overlay))
    live = live_replay(recording, overlay, times)
    unchecked: set[str] = set()  # nodes changed in either since they were last compared, drawn
    frames = zip(times, scenes_by_frame(shared, times), scenes_by_frame(live, times), strict=True)
    for k, (t, (in_file, file_changed), (in_view, view_changed)) in enumerate(frames):
        assert in_file.keys() == in_view.keys(), (t, in_file.keys() ^ in_view.keys())
        unchecked |= file_changed | view_changed
        for name in list(in_view) if k in (0, len(times) - 1) else unchecked & in_view.keys():
            assert_same_node(name, in_file[name], in_view[name], t)
            unchecked.discard(name)


def test_the_file_holds_the_runs_frames_on_its_timeline(runs):
    recording = runs["sim"]
    times = share.frame_times(recording)
    html = share.share_html(recording)
    shared = decode(html)
    assert shared["viserVersion"] == viser.__version__
    assert shared["durationSeconds"] == pytest.approx(len(times) / share.EXPORT_RATE)
    stamps = [t for t, _ in shared["messages"]]
    assert stamps == sorted(stamps) and stamps[-1] == pytest.approx(times[-1]), "one frame every 1/30 s, in order"
    assert times[-1] >= recording.duration > times[-2]
    # The body is where the run was at each frame.
    poses = recording.clip.sampled_at(times)
    for k, (scene, _changed) in enumerate(scenes_by_frame(shared, times)):
        assert np.allclose(scene["/chute/body"]["position"], to_scene(poses.x[k], poses.y[k]))
    # Every touchdown was marked where the foot met the wall; the rings keep the last ones.
    markers = [m for _t, m in shared["messages"] if m.get("name", "").startswith("/chute/touchdowns/")]
    placed = [m["position"] for m in markers if m["type"] == "SetPositionMessage"]
    assert len(placed) == len(recording.touchdowns) > TOUCHDOWN_MARKERS
    assert np.allclose(np.array(placed)[:, 2], recording.touchdowns[:, 2])
    assert len({m["name"] for m in markers}) == TOUCHDOWN_MARKERS
    trails = {m["name"] for _t, m in shared["messages"] if m.get("name", "").startswith("/chute/trail/jump_")}
    assert len(trails) == TRAIL_JUMPS


def test_the_file_plays_from_disk_with_nothing_fetched(runs):
    html = share.share_html(runs["sim"])
    assert html.lower().startswith("<!doctype html>")
    assert "window.__VISER_EMBED_DATA__" in html and "__VISER_EMBED_CONFIG__" in html
    # Scripts, styles and fonts are inlined: no address to fetch, from the network or from disk.
    assert not re.search(r"""<(script|link|img)[^>]+(src|href)\s*=\s*["']?(https?:)?//""", html, re.IGNORECASE)
    assert not re.search(r"""<script[^>]+src\s*=""", html, re.IGNORECASE)


def test_a_run_longer_than_ten_minutes_is_cut_at_ten(runs):
    recording = runs["sim"]
    times = share.frame_times(recording)
    assert times[-1] < share.MAX_EXPORT_SECONDS or pytest.skip("the test run is longer than the cut")
    stretched = dataclasses.replace(recording, clip=_slowed(recording.clip, 20.0))
    assert share.frame_times(stretched)[-1] == pytest.approx(share.MAX_EXPORT_SECONDS, abs=1 / share.EXPORT_RATE)


def _slowed(clip, factor):
    return type(clip)(**{name: getattr(clip, name) * (factor if name == "time" else 1) for name in clip.COLUMNS})


# What the file says it is ------------------------------------------------------------------------
def _head(html: str) -> tuple[str, str, str]:
    """The file's title, its description and the caption over its scene, as written (escaped)."""
    title = re.search(r"<title>([^<]*)</title>", html).group(1)
    description = re.search(r'<meta name="description" content="([^"]*)"', html).group(1)
    caption = re.search(r'<div id="parkourlab-caption"[^>]*>([^<]*)</div>', html).group(1)
    return title, description, caption


def test_the_file_is_titled_and_described_by_its_run(runs):
    """It was titled "Viser" and described as "Viser client": a file mailed or kept said nothing of
    the run. Now its title names the run and its description (shown over the scene too) says its
    id, kind, controls, jumps, climb and date."""
    recording = runs["sim"]
    title, description, caption = _head(share.share_html(recording))
    assert title == f"ParkourLab run {recording.run_id} (sim, 30°:0.87, 30°:0.9)"
    assert description == caption
    assert description.startswith(f"ParkourLab run {recording.run_id}, simulated: left psi0 30°, zeta0 0.87 l0;")
    assert f"right psi0 30°, zeta0 0.9 l0; {JUMPS} jumps, " in description, description
    assert re.search(r"; climb \d+\.\d{3} l0; stored \d{4}-\d\d-\d\d \d\d:\d\d UTC\.$", description), description
    robot = _head(share.share_html(runs["robot"], runs["sim"]))
    legs = "30°:0.87, 30°:0.9"
    robot_id = runs["robot"].run_id
    assert robot[0] == f"ParkourLab run {robot_id} (robot, {legs}), ghost run {recording.run_id} (sim, {legs})"
    assert ", on the robot: " in robot[1] and f"Ghost: ParkourLab run {recording.run_id}, simulated" in robot[1]


def test_the_files_title_and_description_are_text(runs):
    markup = '</title><script>window.__xss=1</script><b a="x">'
    odd = dataclasses.replace(runs["sim"], label=markup, description=markup)
    html = share.share_html(odd)
    plain = share.share_html(runs["sim"])
    assert markup not in html and html.count("<script") == plain.count("<script"), "no element made of it"
    title, description, caption = _head(html)
    escaped = "&lt;/title&gt;&lt;script&gt;window.__xss=1&lt;/script&gt;&lt;b a=&quot;x&quot;&gt;"
    assert title == f"ParkourLab {escaped}" and description == caption == escaped
