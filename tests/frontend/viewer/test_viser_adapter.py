"""The adapter over viser's internals (frontend/viewer/viser_adapter.py), pinned to the viser it
was written for: an upgrade fails here first, saying what to check, instead of breaking the
shared files or the Origin check silently.
"""

from __future__ import annotations

import base64
import importlib.metadata
import re

import numpy as np
import pytest
import viser

from frontend.viewer import viser_adapter
from tests.frontend.viewer.test_share import decode_recording


@pytest.fixture
def server():
    server = viser.ViserServer(host="127.0.0.1", port=0, verbose=False)
    yield server
    server.stop()


def test_the_installed_viser_is_the_one_the_adapter_was_written_for():
    installed = importlib.metadata.version("viser")
    assert installed == viser_adapter.WRITTEN_FOR, (
        f"viser {installed} is installed; frontend/viewer/viser_adapter.py was written for "
        f"{viser_adapter.WRITTEN_FOR}. Check what it reads of viser's internals (ViserServer._websock_server, "
        "WebsockServer._live_connections and _background_event_loop; StateSerializer._messages, "
        "_binary_buffers, _time and _handler._record_lock/_record_handles; viser._messages' scene "
        "messages; viser.infra._infra._append_aligned_buffers; client/build/index.html) against the new "
        "StateSerializer.serialize and as_html, run this file, then set WRITTEN_FOR."
    )


def test_the_adapter_finds_everything_it_reads_of_viser(server):
    assert viser_adapter.missing(server) == []
    assert isinstance(viser_adapter.live_connections(server), dict)
    assert viser_adapter.event_loop(server) is not None, "the websocket server runs on its own loop"


def test_a_viser_that_moved_them_is_named_not_misread():
    class Moved:  # what a viser whose internals moved would look like
        _websock_server = object()

    with pytest.raises(viser_adapter.ViserInternalsChanged, match="_live_connections") as raised:
        viser_adapter.live_connections(Moved())
    assert viser_adapter.WRITTEN_FOR in str(raised.value)


def _same_ops(scene) -> None:
    """Scene changes recorded by the serializers taken before them."""
    box = scene.add_box("/a", color=(240, 150, 0), dimensions=(0.1, 0.2, 0.3), position=(1.0, 0.0, 0.0))
    box.position = (0.5, 0.0, 2.0)
    scene.add_line_segments("/l", points=np.ones((3, 2, 3)), colors=(60, 60, 60), thickness=0.002)


def test_serialize_lays_a_recording_out_as_viser_does(server):
    ours, theirs = server.get_scene_serializer(), server.get_scene_serializer()
    _same_ops(server.scene)
    for serializer in (ours, theirs):
        serializer.insert_sleep(0.5)
    mine = decode_recording(viser_adapter.serialize(ours, level=3))
    viser_own = decode_recording(theirs.serialize())
    assert mine["durationSeconds"] == viser_own["durationSeconds"] == 0.5
    assert mine["viserVersion"] == viser_own["viserVersion"] == viser.__version__
    assert _resolved(mine["messages"], None) == _resolved(viser_own["messages"], None)
    handler = ours._handler
    assert ours not in handler._record_handles, "the recording is ended: the server no longer feeds it"


def test_embed_makes_the_page_as_viser_does(server):
    serializer = server.get_scene_serializer()
    _same_ops(server.scene)
    page = serializer.as_html()
    data = re.search(r'window\.__VISER_EMBED_DATA__="([^"]*)"', page).group(1)
    assert viser_adapter.embed(base64.b64decode(data)) == page


def test_the_writer_writes_what_viser_records_for_the_same_handle_calls():
    server = viser.ViserServer(host="127.0.0.1", port=0, verbose=False)
    try:
        scene = server.scene
        box = scene.add_box("/a", color=(240, 150, 0), dimensions=(0.1, 0.2, 0.3), position=(1.0, 0.0, 0.0))
        line = scene.add_line_segments("/l", points=np.zeros((1, 2, 3)), colors=(60, 60, 60), thickness=0.002)
        label = scene.add_label("/t", "0.00 m", position=(0.1, 0.0, 0.0), font_screen_scale=0.7)
        serializer = server.get_scene_serializer()
        writer = viser_adapter.RecordingWriter(serializer, 1)
        start = len(serializer._messages)
        points = np.random.default_rng(1).normal(size=(4, 2, 3))
        box.position = (0.5, 0.0, 2.0)
        box.visible = False
        box.dimensions = (0.1, 0.2, 4.0)
        line.points = points
        line.colors = np.full((4, 2, 3), 7, dtype=np.uint8)
        scene.add_box("/b", color=(240, 150, 0), dimensions=(0.1, 0.2, 0.3), position=(0.0, 0.0, 3.0))
        scene.add_line_segments("/m", points=points, colors=(60, 60, 60), thickness=0.002)
        scene.add_label("/u", "0.25 m", position=(0.1, 0.0, 0.25), font_screen_scale=0.7)
        viser_wrote = [message for _t, message in serializer._messages[start:]]
        writer.position("/a", (0.5, 0.0, 2.0))
        writer.visible("/a", False)
        writer.update("/a", "dimensions", (0.1, 0.2, 4.0))
        writer.update("/l", "points", points.astype(np.float32))
        writer.update("/l", "colors", np.full((4, 2, 3), 7, dtype=np.uint8))
        writer.make_like("/a", "/b", position=(0.0, 0.0, 3.0))
        writer.make_like("/l", "/m", points=points.astype(np.float32))
        writer.make_like("/t", "/u", text="0.25 m", position=(0.1, 0.0, 0.25))
        buffers = serializer._binary_buffers
        resolved = [_resolved(message, buffers) for message in writer.frames[0]]
        assert resolved == [_resolved(message, buffers) for message in viser_wrote]
        assert label.text == "0.00 m"
    finally:
        server.stop()


def _resolved(value, buffers):
    """Placeholders replaced by (dtype, bytes): equal when they stand for equal arrays."""
    if isinstance(value, np.ndarray):
        return (value.dtype.str, value.tobytes())
    if isinstance(value, dict):
        if "__binary_index" in value:
            return (value["dtype"], bytes(buffers[value["__binary_index"]]))
        return {key: _resolved(item, buffers) for key, item in value.items()}
    if isinstance(value, list | tuple):
        return [_resolved(item, buffers) for item in value]
    return value
