"""ParkourLab's numerical core: the ParkourBot bipedal SLIP model (see docs/model.md).

Data flows parameters -> simulate -> analyse, one package per concept, each importing only those
above it in this list (import-linter holds it: pyproject.toml):

- :mod:`sim_core.model` — what to simulate (parameters, presets, controls, walls, the noise model)
  and the compiled kernels that simulate it: stance, one jump, the Poincaré map, full paths;
- :mod:`sim_core.section` — the map's gaits: fixed points and their stability, the gait search
  (:func:`~sim_core.section.gait_search.gait_of`: the gait of a control schedule), the atlas;
- :mod:`sim_core.basins` — basins of attraction, and energy sweeps of a gait with its basin;
- :mod:`sim_core.viability` — viability kernels (vibly's semantics) and the guard built on them;
- :mod:`sim_core.control` — control laws, controllers and their designs, the closed loop, the study;
- :mod:`sim_core.robustness` — MJTF, the MFPT chain and splitting, under the noise model;
- :mod:`sim_core.calibration`, :mod:`sim_core.climb` — the model fitted to tracked runs, and the
  climb in real time that the 3D view and the virtual robot drive;
- :mod:`sim_core.chunks` (big studies as chunks), :mod:`sim_core._jit` (how kernels compile),
  :mod:`sim_core.bench` (``parkour bench``: the kernel against scipy).

No web, database or plotting imports here. The names below load on first use (PEP 562): importing
``sim_core`` or a light module such as :mod:`sim_core.model.controls` does not load numba or scipy, so a
command that only needs its options starts at once.
"""

from __future__ import annotations

import importlib

# Public name -> the module that defines it.
_EXPORTS = {
    "ClimbEnd": "climb.records",
    "ClimbSetup": "climb.records",
    "ControlSchedule": "model.controls",
    "LegControl": "model.controls",
    "Failure": "model.failures",
    "ParameterError": "model.errors",
    "FixedPointNotFound": "model.errors",
    "FixedPoint": "section.fixed_points",
    "characterize": "section.fixed_points",
    "find_fixed_point": "section.fixed_points",
    "map_jacobian": "section.fixed_points",
    "minimal_period": "section.fixed_points",
    "search_gaits": "section.gait_search",
    "gait_of": "section.gait_search",
    "NoGaitFound": "model.errors",
    "ModelParams": "model.params",
    "PhysicalParams": "model.params",
    "Scales": "model.params",
    "Orbit": "model.poincare",
    "OrbitBatch": "model.poincare",
    "iterate_map": "model.poincare",
    "iterate_map_batch": "model.poincare",
    "PRESETS": "model.presets",
    "PAPER_GAITS": "model.presets",
    "START_GUESS": "model.presets",
    "get_preset": "model.presets",
    "Trajectory": "model.trajectory",
    "simulate_trajectory": "model.trajectory",
    "Wall": "model.walls",
    "wall_of": "model.walls",
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
