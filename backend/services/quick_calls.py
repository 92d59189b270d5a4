"""The quick calls: the map, a sampled path, a gait and a run to store, answered from a compute worker.

The functions here are what the service's quick compute workers run (:mod:`backend.workers.pools`):
module-level, with picklable arguments and results. The compiled kernels (numba, and scipy for
the fixed points) load with a worker's first call, not with the service, so ``parkour serve``
answers before they have loaded; :func:`warm_up` (handed to the pools by ``create_app``) loads
them in each worker at start-up. Hence the imports inside the functions below.
"""

from __future__ import annotations

import itertools
import math
import threading
import time
from collections.abc import Callable
from dataclasses import asdict
from typing import TYPE_CHECKING, Any

import numpy as np

from backend.jobs.base import gait_not_found_as_parameter_error, schedule_of
from backend.schemas import FixedPointIn, MapIn, RunCreate, TrajectoryIn
from backend.services.presets import InSession, preset_resolved, resolve_model
from backend.services.provenance import current_code_version
from backend.store.run_record import RunRecord
from backend.store.trajectory_blob import pack_trajectory
from backend.workers.pools import as_json
from experiments.manifest import json_safe
from sim_core.model.controls import ControlSchedule
from sim_core.model.errors import FixedPointNotFound
from sim_core.model.params import ModelParams
from sim_core.model.presets import START_GUESS, get_preset

if TYPE_CHECKING:
    from backend.workers.pools import ComputePool
    from sim_core.section.fixed_points import FixedPoint

# numba's default threading layer (workqueue) aborts the process if two threads launch
# parallel kernels at once; threads of one process that run kernels take turns through this lock
# (in the service's own process, only the 3D view and the robot's controller still do).
KERNEL_LOCK = threading.Lock()


def warm_up() -> None:
    """Load the kernels a first request needs (from numba's cache, or compiled once) and scipy's
    solver: one short map, path and gait, off the request path."""
    with KERNEL_LOCK:
        from sim_core.model.trajectory import simulate_trajectory
        from sim_core.section.gait_search import gait_of

        model, schedule = get_preset("paper").to_model(), ControlSchedule.from_degrees([(30.0, 0.9)])
        gait = gait_of(model, schedule, guess=START_GUESS)
        simulate_trajectory(model, schedule, gait.state, 1)


async def computed(in_session: InSession, compute: ComputePool, work: Callable[[Any], dict], body) -> bytes:
    """A quick call's answer as JSON: ``body``'s stored preset resolved (through ``in_session`` only
    when the store must be read), then ``work(body)`` in the quick compute worker, which encodes
    the JSON too — the service's process computes nothing and waits in no thread."""
    body = await preset_resolved(in_session, body)
    return await compute.call(as_json, work, body)


def map_orbit(body: MapIn) -> dict:
    from sim_core.model.poincare import iterate_map

    start = (body.start.xdot, body.start.ydot)
    with KERNEL_LOCK:
        return iterate_map(body.model.params(), schedule_of(body.controls), start, body.jumps).to_dict()


def trajectory_columns(body: TrajectoryIn) -> dict:
    from sim_core.model.trajectory import simulate_trajectory

    start = (body.start.xdot, body.start.ydot)
    model = body.model.params()
    path = simulate_trajectory(model, schedule_of(body.controls), start, body.jumps, sample_rate=body.rate)
    scales = resolve_model(None, body.model.preset).robot.scales  # l0 and g are the preset's: they set the units
    return json_safe(
        {
            "units": path.units,
            "columns": path.columns(),
            "touchdown_times": path.touchdown_times,
            "failure": None if path.failure is None else {"code": path.failure.code, "jump": path.failed_jump},
            "walls_x": [-model.d_hat / 2, model.d_hat / 2],  # docs/model.md §2.1: x = 0 on the centre line
            "si": {
                "preset": body.model.preset,
                "l0_m": scales.length,
                "time_s": scales.time,
                "speed_m_per_s": scales.velocity,
            },
        }
    )


def fixed_point(body: FixedPointIn) -> dict:
    model, schedule = body.model.params(), schedule_of(body.controls)
    with KERNEL_LOCK:
        return _gait_of(model, schedule, body.period, body.guess).to_dict()


def _gait_of(model: ModelParams, schedule: ControlSchedule, period: int | None, guess) -> FixedPoint:
    """:func:`sim_core.section.gait_search.gait_of` for a request. ``guess`` is the request's state
    (``xdot``, ``ydot``) or None."""
    from sim_core.section.gait_search import gait_of

    with gait_not_found_as_parameter_error():
        return gait_of(model, schedule, period, None if guess is None else (guess.xdot, guess.ydot))


def simulate_run(body: RunCreate, world: dict | None = None) -> RunRecord:
    """Run the map (and the sampled path if asked): the run to store (its tags are the caller's);
    in ``world`` (its §8 JSON in ``l0``) where given, the climb of ``parkour climb``."""
    from sim_core.model.poincare import iterate_map
    from sim_core.model.trajectory import simulate_trajectory

    model, schedule = body.model.params(), schedule_of(body.controls)
    start = (body.start.xdot, body.start.ydot)
    began = time.perf_counter()
    trajectory = None
    if world is not None:
        results, failure_code, jumps_completed, climb, trajectory = _world_climb(body, model, schedule, start, world)
    else:
        with KERNEL_LOCK:
            orbit = iterate_map(model, schedule, start, body.jumps)
            if body.trajectory_rate is not None:
                path = simulate_trajectory(model, schedule, start, body.jumps, sample_rate=body.trajectory_rate)
                trajectory = pack_trajectory(path.columns())
        results = orbit.to_dict()
        failure_code = None if orbit.failure is None else orbit.failure.code
        jumps_completed, climb = orbit.jumps_completed, float(np.sum(orbit.rises))
    if body.fixed_point:
        results["fixed_point"] = _gait_near(model, schedule, start)
    return RunRecord(
        kind="sim",
        status="done",
        duration_s=time.perf_counter() - began,
        code_version=current_code_version(),
        model=asdict(model) | {"mu": model.mu if np.isfinite(model.mu) else None},
        controls=[[leg.psi0_deg, leg.zeta0] for leg in body.controls],
        start_state=list(start),
        jumps=body.jumps,
        failure_code=failure_code,
        jumps_completed=jumps_completed,
        climb=climb,
        results=json_safe(results),
        trajectory=trajectory,
    )


def _world_climb(body: RunCreate, model, schedule, start, document: dict):
    """A run in a world: ``(results, failure code, jumps completed, climb [l0], path or None)``; the
    results are ``parkour climb``'s touchdowns and failure, with each jump's rise of the foot."""
    from sim_core.world.climb import climb_world
    from sim_core.world.files import world_from_document
    from sim_core.world.trajectory import simulate_world_trajectory

    world, trajectory = world_from_document(document), None
    with KERNEL_LOCK:
        if body.trajectory_rate is None:
            climb = climb_world(model, world, schedule, start, body.jumps)
        else:
            path, climb = simulate_world_trajectory(model, world, schedule, start, body.jumps,
                                                    sample_rate=body.trajectory_rate)  # fmt: skip
            trajectory = pack_trajectory(path.columns())
    results = climb.to_dict()
    touchdowns = results["touchdowns"]
    feet = [td["y"] - height for td, height in zip(touchdowns, _leg_heights(schedule, len(touchdowns)), strict=True)]
    results["rises"] = [after - before for before, after in itertools.pairwise(feet)]
    failure_code = None if climb.failure is None else climb.failure.code
    return results, failure_code, len(touchdowns) - 1, float(sum(results["rises"])), trajectory


def _leg_heights(schedule, touchdowns: int) -> list[float]:
    """How far each touchdown's body is above its foot [l0]: its leg's ``zeta0 sin psi0``."""
    return [schedule[k].zeta0 * math.sin(schedule[k].psi0) for k in range(touchdowns)]


def _gait_near(model, schedule, start) -> dict:
    """The period-m gait nearest the start state (m: the schedule length), or why there is none."""
    from sim_core.section.gait_search import gait_of

    try:
        with KERNEL_LOCK:
            gait = gait_of(model, schedule, guess=start)
    except FixedPointNotFound as error:
        return {"found": False, "reason": str(error)}
    return {"found": True, **gait.to_dict()}
