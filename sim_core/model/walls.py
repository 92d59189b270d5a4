"""The two walls, and which one jump ``k`` stands on (docs/model.md §2, §4).

One vocabulary for left and right everywhere outside the radio codec: a :class:`Wall` is
``LEFT = -1`` (the wall at ``x = -d/2``) or ``RIGHT = +1`` (at ``x = +d/2``), so ``wall * d/2`` is
the wall's ``x`` and ``-wall`` is the other one. A leg is named by the wall it reaches for: the
left leg stands on the left wall. Jump 0 stands on the left wall and the walls alternate, so
jump ``k`` uses the left leg for even ``k`` and the right leg for odd ``k``.

The protocol's ``backend.robot.messages.Leg`` keeps its wire values (0, 1) and converts with
``Leg.of(wall)`` and ``leg.wall``.
"""

from __future__ import annotations

from enum import IntEnum

import numpy as np


class Wall(IntEnum):
    """A wall of the chute; the value is the sign of its ``x``."""

    LEFT = -1
    RIGHT = 1

    @property
    def other(self) -> Wall:
        """The wall across the chute."""
        return Wall(-self.value)

    @property
    def code(self) -> str:
        """``"left"`` or ``"right"``, as JSON and the UI spell it."""
        return self.name.lower()


def wall_of(jump: int) -> Wall:
    """The wall jump ``jump`` (0-based) stands on: the left for even jumps, the right for odd."""
    return Wall.LEFT if jump % 2 == 0 else Wall.RIGHT


def walls_of(jumps) -> np.ndarray:
    """:func:`wall_of` for an array of jump indices: the walls' values (-1, +1), same shape."""
    return np.where(np.asarray(jumps) % 2 == 0, int(Wall.LEFT), int(Wall.RIGHT))
