"""ParkourLab's numerical core: the ParkourBot bipedal SLIP model (see model.md).

Data flows parameters -> simulate -> analyse:

- :mod:`sim_core.params`, :mod:`sim_core.presets`, :mod:`sim_core.controls` — what to simulate;
- :mod:`sim_core.integrate`, :mod:`sim_core.stride` — compiled kernels (stance, one jump, orbits);
- :mod:`sim_core.poincare`, :mod:`sim_core.trajectory` — the validated map and full paths;
- :mod:`sim_core.fixed_points` — periodic gaits, their stability, a gait search, and
  :func:`~sim_core.fixed_points.gait_of`, the gait of a control schedule;
- :mod:`sim_core.basin`, :mod:`sim_core.sweep`, :mod:`sim_core.mjtf`,
  :mod:`sim_core.closed_loop` (with :mod:`sim_core.noise`) — the lab's studies (docs/analyses.md).

No web, database or plotting imports here.
"""

from sim_core.controls import ControlSchedule, LegControl
from sim_core.failures import Failure
from sim_core.fixed_points import (
    FixedPoint,
    FixedPointNotFound,
    NoGaitFound,
    characterize,
    find_fixed_point,
    gait_of,
    map_jacobian,
    minimal_period,
    search_gaits,
)
from sim_core.params import ModelParams, PhysicalParams, Scales
from sim_core.poincare import Orbit, OrbitBatch, iterate_map, iterate_map_batch
from sim_core.presets import PAPER_GAITS, PRESETS, START_GUESS, get_preset
from sim_core.trajectory import Trajectory, simulate_trajectory
from sim_core.validation import ParameterError

__all__ = [
    "PAPER_GAITS",
    "PRESETS",
    "START_GUESS",
    "ControlSchedule",
    "Failure",
    "FixedPoint",
    "FixedPointNotFound",
    "LegControl",
    "ModelParams",
    "NoGaitFound",
    "Orbit",
    "OrbitBatch",
    "ParameterError",
    "PhysicalParams",
    "Scales",
    "Trajectory",
    "characterize",
    "find_fixed_point",
    "gait_of",
    "get_preset",
    "iterate_map",
    "iterate_map_batch",
    "map_jacobian",
    "minimal_period",
    "search_gaits",
    "simulate_trajectory",
]
