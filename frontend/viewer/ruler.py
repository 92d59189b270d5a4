"""What the chute's walls and height ruler gain as they grow ahead of the robot
(:meth:`frontend.viewer.scene.ChuteScene.growth`): pure geometry, no viser. Scene frame as
:mod:`frontend.viewer.geometry` (``z`` up, ``y`` depth); lengths in metres.

The ruler stands at the front of the chute on the left wall's inner face: its spine goes up from
the floor, ticks every 5 cm reach into the chute (longer at each 25 cm, which are labelled). It is
drawn in sections, each from the old top to the new one: ``/chute/ruler`` first, then
``/chute/ruler/part_k``, its labels ``/chute/ruler/label_i``; all hang from the first, so moving
it (a world's left side: ``ChuteScene.set_world``) moves the whole ruler.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from frontend.viewer.geometry import ruler_ticks

MAJOR_TICK, MINOR_TICK = 0.04, 0.02  # [m] how far a tick reaches into the chute
LABEL_GAP = 0.045  # [m] a label's start from the spine


@dataclass(frozen=True)
class Growth:
    """What the walls and the ruler gain when they grow to ``top`` [m] (:meth:`ChuteScene.growth`):
    the walls' new dimensions and positions, a ruler section (its node's name and segments: the
    spine's new stretch and the new ticks) and the new height labels (name, text, position)."""

    top: float
    wall_dimensions: tuple[float, float, float]
    wall_positions: tuple[tuple[float, float, float], ...]
    section: str
    segments: np.ndarray
    labels: tuple[tuple[str, str, tuple[float, float, float]], ...]


def grown(
    below: float, top: float, *, sections: int, labels: int, spine: tuple[float, float],
    wall_size: tuple[float, float], wall_x: Sequence[float],
) -> Growth:  # fmt: skip
    """The walls and ruler grown from ``below`` to ``top`` [m]: ``sections`` and ``labels`` drawn so
    far (none: the first section, from the floor), the spine at ``spine`` (its ``x`` and ``y``
    [m]), the walls ``wall_size`` (thickness, depth) [m] with their centres at ``wall_x`` [m]."""
    inner, front = spine
    fresh, majors = ruler_ticks(top, above=below if sections else -np.inf)
    length = np.where(np.isin(fresh, majors), MAJOR_TICK, MINOR_TICK)
    starts = np.column_stack([np.full(fresh.size, inner), np.full(fresh.size, front), fresh])
    ends = starts + np.column_stack([length, np.zeros(fresh.size), np.zeros(fresh.size)])
    stretch = np.array([[[inner, front, below if sections else 0.0], [inner, front, top]]])
    return Growth(
        top=top,
        wall_dimensions=(*wall_size, top),
        wall_positions=tuple((x, 0.0, 0.5 * top) for x in wall_x),
        section="/chute/ruler" if sections == 0 else f"/chute/ruler/part_{sections}",
        segments=np.concatenate([stretch, np.stack([starts, ends], axis=1)]),
        labels=tuple(
            (f"/chute/ruler/label_{i}", f"{mark:.2f} m", (inner + LABEL_GAP, front, float(mark)))
            for i, mark in enumerate(majors, start=labels)
        ),
    )
