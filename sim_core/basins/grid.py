"""The grid of start states a basin is computed over, and the basin's default convergence test.

A light module (numpy only, no kernels): the ``parkour basin`` options and the API's job specs
read their defaults and check a grid here without loading the compiled basin kernels of
:mod:`sim_core.basins.basin`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from sim_core.model.validation import ParameterError, check_interval, check_range

DEFAULT_TOLERANCE = 0.02  # [sqrt(g l0)]: inside the linear region of a stable gait, far above integrator noise
DEFAULT_JUMPS = 60
DEFAULT_HALF_WIDTH = 1.5  # [sqrt(g l0)]: default window half-width around the gait's state
DEFAULT_BASIN_WINDOW = ((-3.0, -0.02), (-2.0, 2.0))  # [sqrt(g l0)]: a fixed window holding the paper gaits' basins
MAX_CELLS = 4_000_000  # a 2000 x 2000 grid; larger grids are almost certainly a typo


@dataclass(frozen=True)
class BasinGrid:
    """The grid of start states: ``cells`` points per axis over closed ranges [sqrt(g l0)].

    ``xdot`` must stay negative (the body flies toward the left wall at the section).
    """

    xdot_range: tuple[float, float]
    ydot_range: tuple[float, float]
    cells: int

    def __post_init__(self):
        cells = self.cells
        if isinstance(cells, bool) or int(cells) != cells or cells < 2:
            raise ParameterError("grid", f"must be an integer >= 2 cells per axis, got {cells!r}")
        if cells * cells > MAX_CELLS:
            raise ParameterError(
                "grid", f"must be at most {math.isqrt(MAX_CELLS)} cells per axis ({MAX_CELLS:,} cells), got {cells}"
            )
        object.__setattr__(self, "cells", int(cells))
        x_low, x_high = check_interval("xdot_range", self.xdot_range)
        if x_high >= 0.0:
            raise ParameterError("xdot_range", f"must lie below 0 (toward the left wall), got [{x_low:g}, {x_high:g}]")
        object.__setattr__(self, "xdot_range", (x_low, x_high))
        object.__setattr__(self, "ydot_range", check_interval("ydot_range", self.ydot_range))

    @classmethod
    def around(cls, state, cells: int, half_width: float = DEFAULT_HALF_WIDTH) -> BasinGrid:
        """A square window of ``2 * half_width`` centred on ``state``, cut off just below xdot = 0."""
        half_width = check_range("half_width", half_width, 0.0, 100.0)
        xdot, ydot = (float(v) for v in state)
        x_high = min(xdot + half_width, -0.01 * half_width)
        return cls((xdot - half_width, x_high), (ydot - half_width, ydot + half_width), cells)

    @property
    def xdot(self) -> np.ndarray:
        return np.linspace(*self.xdot_range, self.cells)

    @property
    def ydot(self) -> np.ndarray:
        return np.linspace(*self.ydot_range, self.cells)

    @property
    def cell_area(self) -> float:
        """Area one grid point stands for [g l0]."""
        return float(np.ptp(self.xdot_range) * np.ptp(self.ydot_range)) / (self.cells - 1) ** 2

    def states(self) -> np.ndarray:
        """Start states, shape (cells * cells, 2), rows in ``[ydot index, xdot index]`` order."""
        xdot, ydot = np.meshgrid(self.xdot, self.ydot)
        return np.column_stack([xdot.ravel(), ydot.ravel()])
