"""ParkourLab's numerical core: the ParkourBot bipedal SLIP model (see docs/model.md).

Data flows parameters -> simulate -> analyse:

- :mod:`sim_core.params`, :mod:`sim_core.presets`, :mod:`sim_core.controls` — what to simulate;
- :mod:`sim_core.integrate`, :mod:`sim_core.stride` — compiled kernels (stance, one jump, orbits);
- :mod:`sim_core.poincare`, :mod:`sim_core.trajectory` — the validated map and full paths;
- :mod:`sim_core.fixed_points`, :mod:`sim_core.gait_search` — periodic gaits and their stability,
  a gait search, and :func:`~sim_core.gait_search.gait_of`, the gait of a control schedule;
- :mod:`sim_core.walls`, :mod:`sim_core.climb` — left and right, and the climb jump after jump
  (the sequencer the 3D view and the virtual robot drive, with the noise and the chute's floor),
  its records in :mod:`sim_core.climb_records`;
- :mod:`sim_core.basin`, :mod:`sim_core.sweep`, :mod:`sim_core.atlas`, :mod:`sim_core.mjtf`,
  :mod:`sim_core.closed_loop` (with :mod:`sim_core.noise`) — the lab's studies (docs/analyses.md),
  split into chunks by :mod:`sim_core.chunks`;
- :mod:`sim_core.reference`, :mod:`sim_core.bench` — the scipy baseline and ``parkour bench``.

No web, database or plotting imports here. The names below load on first use (PEP 562): importing
``sim_core`` or a light module such as :mod:`sim_core.controls` does not load numba or scipy, so a
command that only needs its options starts at once.
"""

from __future__ import annotations

import importlib

# Public name -> the module that defines it.
_EXPORTS = {
    "ClimbEnd": "climb_records",
    "ClimbSetup": "climb_records",
    "ControlSchedule": "controls",
    "LegControl": "controls",
    "Failure": "failures",
    "ParameterError": "errors",
    "FixedPointNotFound": "errors",
    "FixedPoint": "fixed_points",
    "characterize": "fixed_points",
    "find_fixed_point": "fixed_points",
    "map_jacobian": "fixed_points",
    "minimal_period": "fixed_points",
    "search_gaits": "gait_search",
    "gait_of": "gait_search",
    "NoGaitFound": "errors",
    "ModelParams": "params",
    "PhysicalParams": "params",
    "Scales": "params",
    "Orbit": "poincare",
    "OrbitBatch": "poincare",
    "iterate_map": "poincare",
    "iterate_map_batch": "poincare",
    "PRESETS": "presets",
    "PAPER_GAITS": "presets",
    "START_GUESS": "presets",
    "get_preset": "presets",
    "Trajectory": "trajectory",
    "simulate_trajectory": "trajectory",
    "Wall": "walls",
    "wall_of": "walls",
}

__all__ = sorted(_EXPORTS)


def __getattr__(name: str):
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module 'sim_core' has no attribute {name!r}")
    value = getattr(importlib.import_module(f"sim_core.{module}"), name)
    globals()[name] = value  # later lookups skip this function
    return value


def __dir__() -> list[str]:
    return sorted({*globals(), *_EXPORTS})
