"""Scene nodes reused in a ring, so a long run draws with a bounded number of them.

- :class:`NodeRing` — the last ``size`` of a kind of node (touchdown markers, past jumps' trails),
  the oldest node reused for the newest item;
- :class:`StreamedTrail` — a path drawn as it grows, cut into pieces of :data:`PIECE_POINTS`
  points so each point is sent to the browser about once (live mode's trails);
- :func:`hidden_lines` — how the trails' line nodes are made: hidden, of one colour and thickness.

:class:`frontend.viewer.scene.ChuteScene` holds them; :mod:`frontend.viewer.share` writes a
ring's items into a recording the way :meth:`NodeRing.show_next` shows them.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import viser

from frontend.viewer.geometry import polyline_segments

PIECE_POINTS = 25  # a piece's points (the next piece starts at its last): 0.24 s of the tracker's 100 Hz


def hidden_lines(scene: viser.SceneApi, color, thickness: float) -> Callable[[str], viser.LineSegmentsHandle]:
    """``make(name)``: a hidden line-segments node ``name`` on ``scene`` (one placeholder segment)."""

    def make(name: str) -> viser.LineSegmentsHandle:
        points = np.zeros((1, 2, 3))
        return scene.add_line_segments(name, points=points, colors=color, thickness=thickness, visible=False)

    return make


class NodeRing:
    """The last ``size`` of a kind of node (touchdown markers, past trails): item ``k`` is drawn by
    node ``prefix + str(k % size)``, made by ``make(name)`` (hidden) the first time it is needed
    and reused after; the oldest item's node shows the newest."""

    def __init__(self, prefix: str, size: int, make):
        self.prefix, self.size, self._make = prefix, size, make
        self.nodes: list = []
        self.count = 0  # items shown since the last clear

    def node(self, k: int):
        """The node that shows item ``k`` (made now if it is new)."""
        slot = k % self.size
        while len(self.nodes) <= slot:
            self.nodes.append(self._make(f"{self.prefix}{len(self.nodes)}"))
        return self.nodes[slot]

    def show_next(self, **props) -> None:
        """Show the next item: its node gets ``props`` (``position``, ``points``) and is made visible."""
        node = self.node(self.count)
        for name, value in props.items():
            setattr(node, name, value)
        node.visible = True
        self.count += 1

    def clear(self) -> None:
        for node in self.nodes:
            node.visible = False
        self.count = 0


class StreamedTrail:
    """A path drawn as it grows, each point sent to the browser about once (live mode: the
    robot's tracked path, the ghost's jump under way).

    viser sends a node's whole ``points`` each time they change, so a trail drawn as one node is
    sent whole every frame, and grows. Here the path is cut into pieces of :data:`PIECE_POINTS`
    points, each starting at the last point of the one before (the line is unbroken). The piece
    under way is node ``prefix + "now"``, sent again as it grows (at most PIECE_POINTS - 1
    segments); a finished piece is shown by a node of a :class:`NodeRing` (``prefix + "piece_k"``)
    and not sent again: the last ``pieces`` finished pieces stay drawn, the oldest node reused
    for the newest. Nodes are made when first needed. :meth:`clear` starts afresh.
    """

    def __init__(self, scene: viser.SceneApi, prefix: str, pieces: int, color, thickness: float):
        self.scene, self.prefix, self.color, self.thickness = scene, prefix, color, thickness
        self._make = hidden_lines(scene, color, thickness)
        self.finished = NodeRing(f"{prefix}piece_", pieces, self._make)
        self.now: viser.LineSegmentsHandle | None = None
        self.piece = np.empty((0, 2))  # the piece under way's points (n, 2) [m]

    def extend(self, points: np.ndarray) -> None:
        """Add ``points`` (n, 2) [m, model plane] to the path's end."""
        if len(points) == 0:
            return
        path = np.concatenate([self.piece, np.asarray(points, dtype=float).reshape(-1, 2)])
        step = PIECE_POINTS - 1
        done = (len(path) - 1) // step  # pieces finished by these points
        # Only the last ``size`` of them would stay drawn.
        for k in range(max(done - self.finished.size, 0), done):
            self.finished.show_next(points=polyline_segments(path[k * step : (k + 1) * step + 1]))
        self.piece = path[done * step :]
        if self.now is None:
            self.now = self._make(f"{self.prefix}now")
            self.now.visible = True
        # One point left: a segment of no length (the next point makes it a line).
        self.now.points = polyline_segments(self.piece if len(self.piece) >= 2 else self.piece[[0, 0]])

    def clear(self) -> None:
        """Nothing drawn; the next point starts a new path."""
        self.finished.clear()
        self.piece = np.empty((0, 2))
        if self.now is not None:
            self.now.points = np.zeros((1, 2, 3))
