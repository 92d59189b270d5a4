"""Rings of reused scene nodes (frontend/viewer/node_rings.py): a ring keeps the last ``size``
items on ``size`` nodes, made when first needed; a streamed trail draws an unbroken path, the
newest part of it, on a bounded number of nodes, each finished piece sent once.

The ring is tested on plain stand-in nodes; the trail on a private viser server's scene, read back
as a browser that connected would get it (tests/frontend/viewer/test_share.py's decoder).
"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest
import viser

from frontend.viewer.node_rings import PIECE_POINTS, NodeRing, StreamedTrail, hidden_lines
from tests.frontend.viewer.modes.test_live import climb, segments_of, trail_drawn
from tests.frontend.viewer.test_share import SceneTree, decode_recording


def browser_scene(server: viser.ViserServer) -> dict:
    """The scene a browser that connected now would get."""
    tree = SceneTree()
    for _t, message in decode_recording(server.get_scene_serializer().serialize())["messages"]:
        tree.apply(message)
    return tree.shown()


class Maker:
    """``make(name)`` for a ring: a hidden stand-in node, and the names made so far."""

    def __init__(self):
        self.made: list[str] = []

    def __call__(self, name: str) -> SimpleNamespace:
        self.made.append(name)
        return SimpleNamespace(name=name, visible=False, position=None)


def test_a_ring_makes_its_nodes_when_first_needed_and_reuses_the_oldest_for_the_newest():
    make = Maker()
    ring = NodeRing("/chute/touchdowns/", 3, make)
    assert make.made == [], "nothing made before an item is shown"
    for k in range(5):
        ring.show_next(position=(float(k), 0.0, 0.0))
    assert make.made == ["/chute/touchdowns/0", "/chute/touchdowns/1", "/chute/touchdowns/2"], "size nodes, no more"
    assert ring.count == 5
    assert [node.position[0] for node in ring.nodes] == [3.0, 4.0, 2.0], "items 3 and 4 on the nodes of 0 and 1"
    assert all(node.visible for node in ring.nodes)
    assert ring.node(7) is ring.nodes[1], "item k is drawn by node k % size"


def test_a_cleared_ring_hides_its_nodes_and_starts_again_at_node_zero():
    make = Maker()
    ring = NodeRing("/chute/trail/jump_", 4, make)
    ring.show_next(points="a")
    ring.show_next(points="b")
    ring.clear()
    assert ring.count == 0 and not any(node.visible for node in ring.nodes)
    ring.show_next(points="c")
    assert (ring.nodes[0].points, ring.nodes[0].visible, ring.nodes[1].visible) == ("c", True, False)
    assert len(make.made) == 2, "its nodes are kept, not made again"


def test_hidden_lines_makes_a_hidden_line_node_of_the_colour_and_thickness_given(server):
    node = hidden_lines(server.scene, (10, 20, 30), 0.004)("/chute/trail/jump_0")
    assert node.name == "/chute/trail/jump_0" and not node.visible
    assert node.thickness == pytest.approx(0.004)
    assert {tuple(color) for color in np.reshape(node.colors, (-1, 3)).tolist()} == {(10, 20, 30)}
    assert "/chute/trail/jump_0" not in browser_scene(server), "a browser draws nothing of it yet"


@pytest.mark.parametrize("chunk", [1, 2, 7, PIECE_POINTS - 1, PIECE_POINTS, 100, 5000])
def test_a_streamed_trail_draws_the_path_however_it_arrives(server, chunk):
    """Points added one at a time or thousands at once: the same unbroken path, its newest part."""
    trail = StreamedTrail(server.scene, "/chute/trail/live/", 4, (0, 0, 0), 0.003)
    path = climb(np.arange(0.0, 7.0, 0.01), 0.1)  # 700 points
    for start in range(0, len(path), chunk):
        trail.extend(path[start : start + chunk])
    shown = trail_drawn(browser_scene(server))
    assert shown == segments_of(path[-(len(shown) + 1) :])
    assert 4 * (PIECE_POINTS - 1) <= len(shown) < 5 * (PIECE_POINTS - 1)
    trail.clear()
    trail.extend(path[:3])
    assert trail_drawn(browser_scene(server)) == segments_of(path[:3]), "cleared: the new path alone"


def test_a_streamed_trail_sends_each_finished_piece_once_on_a_bounded_set_of_nodes(server):
    trail = StreamedTrail(server.scene, "/chute/ghost/live/", 3, (0, 0, 0), 0.003)
    path = climb(np.arange(0.0, 5.0, 0.01), 0.1)  # 500 points: 20 pieces and a part
    for point in path:
        trail.extend(point[None, :])
    names = {name for name in browser_scene(server) if name.startswith("/chute/ghost/live/")}
    assert names == {"/chute/ghost/live/now", *(f"/chute/ghost/live/piece_{k}" for k in range(3))}
    step = PIECE_POINTS - 1
    assert trail.finished.count == (len(path) - 1) // step, "every piece finished was shown once"
    assert len(trail.piece) == (len(path) - 1) % step + 1, "the piece under way starts where the last ended"


def test_a_burst_of_points_sends_only_the_pieces_that_stay_drawn(server):
    serializer = server.get_scene_serializer()
    trail = StreamedTrail(server.scene, "/chute/trail/live/", 3, (0, 0, 0), 0.003)
    trail.extend(climb(np.arange(0.0, 7.0, 0.01), 0.1))  # 700 points at once: 29 pieces finished
    sent = [
        message["name"]
        for _t, message in decode_recording(serializer.serialize())["messages"]
        if message.get("name", "").startswith("/chute/trail/live/piece_") and "points" in message.get("updates", {})
    ]
    assert sorted(sent) == [f"/chute/trail/live/piece_{k}" for k in range(3)], "the last 3, each sent once"


def test_a_streamed_trail_of_one_point_draws_a_segment_of_no_length(server):
    trail = StreamedTrail(server.scene, "/chute/trail/live/", 2, (0, 0, 0), 0.003)
    trail.extend(np.empty((0, 2)))
    assert trail.now is None, "no points: no node made"
    trail.extend(np.array([[0.1, 0.2]]))
    segment = trail.now.points.reshape(-1, 2, 3)
    assert segment.shape == (1, 2, 3) and np.array_equal(segment[0, 0], segment[0, 1])
    assert trail_drawn(browser_scene(server)) == set(), "nothing of any length is drawn"
