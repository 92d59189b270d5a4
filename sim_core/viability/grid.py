"""The grid of a viability computation (:mod:`sim_core.viability.engine`), and the ParkourBot's default
one: numpy only, so that the ``parkour viability`` options and the service's job schemas read
the defaults and check a grid without loading the compiled kernels.

:func:`section_grid` lays out the grid of the mid-chute section (:mod:`sim_core.viability.step_map`):
60 x 60 velocity states and 20 x 20 leg commands by default, the 1.44 million pairs the issue's
benchmark asks for.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from sim_core.model.validation import ParameterError, check_interval, check_range

MAX_PAIRS = 50_000_000  # 800 MB of bins for a 2-D state: past this the grid is almost certainly a typo
MAX_DIMENSIONS = 4  # per side: 2**4 corners per bin at most
# Defaults: with the leg free over its range nearly every velocity the paper's gaits fly at (xdot
# about 0.7-1.6, ydot -0.3-1.4) is viable; the paper preset's kernel ends near xdot 4 and
# ydot -5 / +4, so the window reaches past that for its edge to show.
DEFAULT_XDOT = (0.05, 4.5)
DEFAULT_YDOT = (-4.5, 4.5)
DEFAULT_PSI0_DEG = (15.0, 55.0)
DEFAULT_ZETA0 = (0.70, 0.98)
DEFAULT_STATES = 60
DEFAULT_ACTIONS = 20
MAX_PITCH_DEG = 30.0


@dataclass(frozen=True)
class ViabilityGrid:
    """The nodes: one strictly increasing 1-D axis per state dimension (2 nodes at least), then per
    action dimension (1 at least: a control held fixed)."""

    state_axes: tuple[np.ndarray, ...]
    action_axes: tuple[np.ndarray, ...]

    def __post_init__(self):
        for side, axes in (("state_axes", self.state_axes), ("action_axes", self.action_axes)):
            if not 1 <= len(axes) <= MAX_DIMENSIONS:
                raise ParameterError(side, f"must hold 1 to {MAX_DIMENSIONS} axes, got {len(axes)}")
            checked = []
            fewest = 2 if side == "state_axes" else 1  # an action axis of one node: a control held fixed
            for number, axis in enumerate(axes):
                values = np.asarray(axis, dtype=np.float64)
                field = f"{side}[{number}]"
                if values.ndim != 1 or values.size < fewest:
                    message = f"must be a 1-D axis of at least {fewest} nodes, got shape {values.shape}"
                    raise ParameterError(field, message)
                if not np.all(np.isfinite(values)) or not np.all(np.diff(values) > 0):
                    raise ParameterError(field, "must be finite and strictly increasing")
                values.setflags(write=False)
                checked.append(values)
            object.__setattr__(self, side, tuple(checked))
        if self.pairs > MAX_PAIRS:
            raise ParameterError(
                "grid", f"must hold at most {MAX_PAIRS:,} state-action pairs, got {self.pairs:,} ({self.shape})"
            )

    @property
    def state_shape(self) -> tuple[int, ...]:
        return tuple(axis.size for axis in self.state_axes)

    @property
    def action_shape(self) -> tuple[int, ...]:
        return tuple(axis.size for axis in self.action_axes)

    @property
    def shape(self) -> tuple[int, ...]:
        return self.state_shape + self.action_shape

    @property
    def pairs(self) -> int:
        return int(np.prod(self.shape))

    def states(self) -> np.ndarray:
        """Every state node, shape (states, ds), in C order of ``state_shape``."""
        return _nodes(self.state_axes)

    def actions(self) -> np.ndarray:
        """Every action node, shape (actions, da), in C order of ``action_shape``."""
        return _nodes(self.action_axes)


def _nodes(axes) -> np.ndarray:
    return np.stack([mesh.ravel() for mesh in np.meshgrid(*axes, indexing="ij")], axis=1)


def section_grid(
    *,
    states: int = DEFAULT_STATES,
    actions: int = DEFAULT_ACTIONS,
    xdot_range: tuple[float, float] = DEFAULT_XDOT,
    ydot_range: tuple[float, float] = DEFAULT_YDOT,
    psi0_deg_range: tuple[float, float] = DEFAULT_PSI0_DEG,
    zeta0_range: tuple[float, float] = DEFAULT_ZETA0,
    pitch_nodes: int = 0,
    pitch_deg: float = 0.0,
) -> ViabilityGrid:
    """A grid of ``states`` nodes per velocity axis and ``actions`` per control axis; with
    ``pitch_nodes`` > 0 a third state axis over ``[-pitch_deg, pitch_deg]`` (an odd count puts
    a node at zero; the axis is symmetric, so a pitch's sign change lands on a node)."""
    check_node_counts(states=states, actions=actions)
    x_low, x_high = check_interval("xdot_range", xdot_range, 0.0, 20.0)
    y_low, y_high = check_interval("ydot_range", ydot_range, -20.0, 20.0)
    state_axes = [np.linspace(x_low, x_high, int(states)), np.linspace(y_low, y_high, int(states))]
    if pitch_nodes:
        if isinstance(pitch_nodes, bool) or int(pitch_nodes) != pitch_nodes or pitch_nodes < 2:
            raise ParameterError("pitch_nodes", f"must be 0 (no pitch axis) or an integer >= 2, got {pitch_nodes!r}")
        limit = check_range("pitch_deg", pitch_deg, 0.0, MAX_PITCH_DEG)
        if limit == 0.0:
            raise ParameterError("pitch_deg", f"must be in (0, {MAX_PITCH_DEG:g}] with a pitch axis, got 0")
        state_axes.append(np.radians(np.linspace(-limit, limit, int(pitch_nodes))))
    return ViabilityGrid(tuple(state_axes), control_axes(actions, psi0_deg_range, zeta0_range))


def control_axes(actions: int, psi0_deg_range, zeta0_range) -> tuple[np.ndarray, np.ndarray]:
    """The action axes: ``actions`` leg angles [rad] over ``psi0_deg_range`` [deg] and as many
    leg lengths over ``zeta0_range`` [l0], each range checked by name."""
    p_low, p_high = check_interval("psi0_range", psi0_deg_range, 1.0, 89.0)
    z_low, z_high = check_interval("zeta0_range", zeta0_range, 0.05, 0.999)
    return np.radians(np.linspace(p_low, p_high, int(actions))), np.linspace(z_low, z_high, int(actions))


def check_node_counts(**counts: int) -> None:
    """Each named count of nodes per axis an integer >= 2, or a ParameterError naming it."""
    for field, count in counts.items():
        if isinstance(count, bool) or int(count) != count or count < 2:
            raise ParameterError(field, f"must be an integer >= 2 nodes per axis, got {count!r}")


def degrees_of(actions: np.ndarray) -> np.ndarray:
    """Actions ``(psi0 [rad], zeta0)`` with psi0 in degrees, for people."""
    out = np.array(actions, dtype=np.float64, copy=True)
    out[..., 0] = np.degrees(out[..., 0])
    return out
