"""A simulated run as an MCAP recording, to open beside a robot run's in Foxglove or Rerun
(docs/service.md, "Recordings"; a robot run's: :mod:`backend.services.mcap_export`).

The run's stored path (``runs.trajectory``: ``time``, ``x``, ``y``, ``foot_x``, ``foot_y``, ``psi``,
``zeta``, ``phase``, ``jump``, nondimensional) is written as a robot run's tracked body is, on the
same topics and in the same schemas, so that one layout shows either:

- ``/tracker/pose``: the body at every sample of the path, ``x`` across the chute from its centre
  line and ``y`` up [m], no pitch (the model's body is a point); the pose, transform and point
  Foxglove and Rerun draw, and ``/plot/height``, from it (:mod:`backend.services.mcap_visuals`);
- ``/touchdowns``: one per touchdown of the run (``results``: the section states and rises of a run
  between parallel walls, the ``touchdowns`` of one in a world), with its leg's controls, its
  section state flipped to the left wall [sqrt(g l0)], the body's and the foot's height [m] (the
  feet where the scheduled legs put them, as the simulation does), its rise [l0] and
  ``poses_fitted`` 0 (nothing was tracked); the touchdown plots from them;
- ``/world/scene`` and ``/world/points``: the chute, its stored world (``runs.world_id``) or the
  parallel walls of its model's ``d_hat`` (:mod:`backend.services.mcap_world`).

A simulation has no commands, telemetry, link or tracker loss, and the model's prediction of it is
itself: those channels (``/commands``, ``/telemetry``, ``/robot/link``, ``/robot/log``,
``/model/prediction``, ``/plot/prediction/rise``) are not in its file.

Units: a robot run's. Lengths are the path's times the robot's leg length ``l0`` and times are
its times ``sqrt(l0/g)``, the ``paper`` preset's (:data:`~backend.services.mcap_world.ROBOT_PRESET`,
the robot of the service's robot runs and the scale stored worlds are drawn and simulated with; a
run stores its nondimensional model only): the metadata's ``scales``.

Time: a simulation has no clock of its own, so its time plays the tracker's
(:mod:`backend.services.mcap_clock`): log time = the run's ``created_at`` + its time ``t`` [s], 0 at
touchdown 0, the path's first sample. The store keeps the sampled path, not the touchdowns'
instants: a touchdown is at its stance's first sample, the first point of the path's sampling grid
(``i / trajectory_rate``) at or after it, less than a sample period late; the last touchdown of a
run that did all its jumps, where the path ends, at the grid's next point after the path's last.
"""

from __future__ import annotations

import math

import numpy as np
from sqlalchemy.orm import Session

from backend.errors import Conflict
from backend.services.mcap_clock import TrackerClock, utc
from backend.services.mcap_recording import Recording, metadata_text, poses, touchdown, with_drawings
from backend.store.models import Run
from backend.store.trajectory_blob import unpack_trajectory
from sim_core.model.controls import ControlSchedule
from sim_core.model.presets import get_preset
from sim_core.model.walls import wall_of

STANCE = 0  # the path's phase column: 0 stance, 1 flight (sim_core.model.trajectory, whose module loads the kernels)
TIME_CONVENTION = (
    "log time = publish time = UTC ns: created_at + t; t the simulation's time [s] (its sqrt(l0/g) times the path's), "
    "0 at touchdown 0; a touchdown at the first point of the path's sampling grid at or after it, its stance's first "
    "sample (backend/services/mcap_sim.py)"
)


def recording(session: Session, run: Run) -> Recording:
    """The recording of simulated run ``run`` (the module's docstring); a Conflict if it was stored
    without its path."""
    if run.trajectory is None:
        raise Conflict(f"run {run.id} is a sim run stored without its path: nothing to record; simulate it again "
                       "with trajectory_rate to export it")  # fmt: skip
    from backend.services.mcap_world import ROBOT_PRESET  # protobuf, Foxglove's schemas: loaded by exports only

    path = unpack_trajectory(run.trajectory)
    scales = get_preset(ROBOT_PRESET).scales
    seconds, metres = path["time"] * scales.time, {axis: path[axis] * scales.length for axis in ("x", "y")}
    at = TrackerClock.of((), run.created_at, 0.0).log_time

    stored = _touchdowns(run, scales.length)
    times = _touchdown_times(path, seconds, len(stored))
    controls = [{"psi0_deg": psi0, "zeta0": zeta0} for psi0, zeta0 in run.controls]
    rises = run.results.get("rises", [])
    messages = {
        "/tracker/pose": [(at(pose["tracker_time"]), pose) for pose in poses(seconds, metres["x"], metres["y"])],
        "/touchdowns": [(at(time), touchdown(td | {"time": time}, controls[k % len(controls)], rises))
                        for k, (td, time) in enumerate(zip(stored, times, strict=True))],
    }  # fmt: skip
    return Recording(run.id, with_drawings(session, run, metres, messages, at(0.0)), _metadata(run, ROBOT_PRESET))


def _touchdowns(run: Run, l0: float) -> list[dict]:
    """The run's touchdowns as a robot run stores its own (:func:`~backend.services.mcap_recording.touchdown`),
    but for their times."""
    results, schedule = run.results, ControlSchedule.from_degrees(run.controls)

    def lift(k: int) -> float:  # the body above the foot at touchdown k [l0], its leg's zeta0 sin psi0
        return schedule[k].zeta0 * math.sin(schedule[k].psi0)

    if "touchdowns" in results:  # in a world: the body at each, in wall coordinates
        found = [(k, -1 if td["side"] == "left" else 1, td["y"], td["xdot"], td["ydot"])
                 for k, td in enumerate(results["touchdowns"])]  # fmt: skip
        rows = [(k, wall, [-wall * xdot, ydot], y, y - lift(k)) for k, wall, y, xdot, ydot in found]
    else:  # parallel walls: the map's section states; the body at height 0 at touchdown 0, as the path
        feet = [-lift(0)]
        for rise in results["rises"][: len(results["states"]) - 1]:
            feet.append(feet[-1] + rise)
        rows = [(k, int(wall_of(k)), state, foot + lift(k), foot)
                for k, (state, foot) in enumerate(zip(results["states"], feet, strict=True))]  # fmt: skip
    return [
        {"index": k, "wall": wall, "state": state, "body_height": body * l0, "foot_height": foot * l0,
         "poses_fitted": 0}
        for k, wall, state, body, foot in rows
    ]  # fmt: skip


def _touchdown_times(path: dict, seconds: np.ndarray, touchdowns: int) -> list[float]:
    """Each touchdown's time [s]: its stance's first sample, the first of the path's sampling grid
    at or after it (the store keeps no touchdown instants); where the path ends before it (the
    last touchdown of a run that did all its jumps), the grid's next point after the path's end."""
    if seconds.size < 2:
        return [0.0] * touchdowns
    order = path["jump"].astype(np.int64) * 2 + (path["phase"] != STANCE)  # stance, flight; jump by jump
    first = np.searchsorted(order, 2 * np.arange(touchdowns), side="left")
    after_end = seconds[-1] + (seconds[-1] - seconds[-2])
    return [float(seconds[i]) if i < seconds.size else float(after_end) for i in first]


def _metadata(run: Run, preset: str) -> dict[str, str]:
    results, scales = run.results, get_preset(preset).scales
    return metadata_text({
        "run_id": run.id,
        "kind": run.kind,
        "status": run.status,
        "created_at": utc(run.created_at).isoformat(),
        "code_version": run.code_version,
        "model": run.model,
        "controls": run.controls,
        "start_state": run.start_state,
        "jumps": run.jumps,
        "jumps_completed": run.jumps_completed,
        "climb": run.climb,
        "failure": results.get("failure"),
        "fixed_point": results.get("fixed_point"),
        "world_id": run.world_id,
        "tags": list(run.tags),
        "scales": {"preset": preset, "l0_m": scales.length, "time_s": scales.time},
        "time_convention": TIME_CONVENTION,
    })  # fmt: skip
