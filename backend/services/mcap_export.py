"""A stored run as an MCAP recording (https://mcap.dev), which Foxglove and Rerun open: a robot
run's or a replay's here, a simulated run's in :mod:`backend.services.mcap_sim`, both made of the
same parts (:mod:`backend.services.mcap_recording`), so that a simulation opens beside a robot run.

A robot run's own channels, protobuf messages of package ``parkourlab`` (topics, fields and units:
:mod:`backend.services.mcap_schemas`):

- ``/tracker/pose``: one message per tracker frame;
- ``/touchdowns``: one per detected touchdown, with the controls it was made with;
- ``/commands``, ``/telemetry``, ``/robot/link``: what the PC sent, what the robot reported, the
  link's state changes;
- ``/model/prediction``: the model's prediction of each touchdown from the first (none with fewer
  than two touchdowns): the Poincaré map's, or in a stored world the model's climb there
  (:mod:`backend.services.run_prediction`; the metadata's ``prediction_model`` says which).

Beside them, the same poses and numbers in the formats Foxglove and Rerun draw as they open the
file (:mod:`backend.services.mcap_visuals`): the body as Foxglove's ``PoseInFrame``,
``FrameTransform`` and ``PointCloud`` in protobuf, the link's changes and the commands as
Foxglove's ``Log``, the height and touchdown series as ROS 2 number arrays, which Rerun plots, and
the chute the run climbed — its stored world, else parallel walls — as a Foxglove ``SceneUpdate``
and a ``PointCloud`` (:mod:`backend.services.mcap_world`).

Timestamps (log time = publish time, UTC nanoseconds since the Unix epoch) are all on one clock,
the tracker's, begun at the run's start: the rule is :mod:`backend.services.mcap_clock`'s.
Messages are written in log-time order (at one time, in the order the channels are registered),
zstd-compressed in chunks, with a summary (message counts per channel).

A replay run has no frames, commands or telemetry of its own: its recording is its source run's
(frames, commands, telemetry, link, and times from the source's start) with the replay's own
touchdowns and prediction. The run's metadata — id, kind, model, controls, code version,
calibration, how it ended — is a Metadata record named ``parkourlab.run`` (text as it is, any
other value as JSON text). A run still running, a replay whose source is gone and a simulated run
without a stored path are refused with a Conflict.
"""

from __future__ import annotations

from typing import BinaryIO

from sqlalchemy.orm import Session

from backend.errors import Conflict
from backend.repositories import runs as stored_runs
from backend.services import mcap_sim
from backend.services.mcap_clock import TrackerClock, utc
from backend.services.mcap_recording import (
    METADATA_NAME,
    Recording,
    metadata_text,
    poses,
    touchdown,
    with_drawings,
    write_recording,
)
from backend.services.robot_records import recorded_leg_for
from backend.store.models import Run
from backend.store.trajectory_blob import unpack_trajectory

__all__ = ["EXPORTED_KINDS", "METADATA_NAME", "Recording", "export_run", "recording_of"]

EXPORTED_KINDS = ("robot", "replay", "sim")
TIME_CONVENTION = (
    "log time = publish time = UTC ns on the tracker's clock: recorded_at + (t - the first frame's t); t a frame's, "
    "touchdown's or prediction's tracker time, a command's or telemetry's tracker_time (the newest frame's when it "
    "was sent or heard), else its Unix time carried to the tracker's clock through the run's (time, tracker_time) "
    "pairs (backend/services/mcap_clock.py)"
)


def export_run(session: Session, run_id: int, stream: BinaryIO) -> dict[str, int]:
    """Write run ``run_id``'s recording to ``stream`` (binary, seekable or not); returns the
    message count per topic. NotFound for a missing run, Conflict for one that is no recording."""
    recording = recording_of(session, run_id)
    write_recording(recording, stream)
    return recording.counts()


def recording_of(session: Session, run_id: int) -> Recording:
    """The recording of a run that has ended: a robot run's, a replay's whose source run is stored,
    or a simulated run's with a stored path (:func:`backend.services.mcap_sim.recording`)."""
    run = stored_runs.get_run(session, run_id)
    if run.kind not in EXPORTED_KINDS:
        raise Conflict(f"run {run_id} is a {run.kind} run: only {', '.join(EXPORTED_KINDS)} runs export as MCAP")
    if run.status == "running":
        raise Conflict(f"run {run_id} is still running; export it once it has ended")
    if run.kind == "sim":
        return mcap_sim.recording(session, run)
    return _recorded(session, run)


def _recorded(session: Session, run: Run) -> Recording:
    """A robot run's recording, or a replay's: its source run's frames, commands, telemetry and link
    with its own touchdowns and prediction."""
    source = run
    if run.kind == "replay":
        source_id = run.results.get("source_run_id")
        source = stored_runs.find(session, source_id) if isinstance(source_id, int) else None
        if source is None:
            raise Conflict(f"replay run {run.id}'s source run {source_id} is gone: its frames were not kept")
    frames = unpack_trajectory(source.trajectory) if source.trajectory is not None else None
    first_frame_time = float(frames["time"][0]) if frames is not None and frames["time"].size else 0.0
    commands, telemetry = source.results.get("commands", []), source.results.get("telemetry", [])
    clock = TrackerClock.of([*commands, *telemetry], source.created_at, first_frame_time)
    at = clock.log_time

    results = run.results
    touchdowns = results.get("touchdowns", [])
    if run.kind == "robot":
        controls = [{"psi0_deg": psi0, "zeta0": zeta0} for psi0, zeta0 in results.get("touchdown_controls", [])]
    else:
        leg_for = recorded_leg_for(source)
        controls = [{"psi0_deg": leg.psi0_deg, "zeta0": leg.zeta0} for leg in map(leg_for, range(len(touchdowns)))]
    rises = results.get("rises", [])
    tracked = [] if frames is None else poses(frames["time"], frames["x"], frames["y"], frames.get("pitch"))
    messages = {
        "/tracker/pose": [(at(pose["tracker_time"]), pose) for pose in tracked],
        "/touchdowns": [
            (at(td["time"]), touchdown(td, controls[k] if k < len(controls) else None, rises))
            for k, td in enumerate(touchdowns)
        ],
        "/commands": _on_clock(clock, commands),
        "/telemetry": _on_clock(clock, telemetry),
        "/model/prediction": [
            (at(touchdowns[k]["time"]), message)
            for k, message in enumerate(_predictions(results.get("prediction"), touchdowns, rises))
        ],
        "/robot/link": _on_clock(clock, source.results.get("transitions", [])),
    }
    drawn = with_drawings(session, source, frames, messages, at(first_frame_time))
    return Recording(run.id, drawn, _metadata(run, source))


def _predictions(prediction: dict | None, touchdowns: list[dict], rises: list) -> list[dict]:
    """One message per predicted touchdown k (the measured touchdown k beside it)."""
    if prediction is None:
        return []
    predicted_rises = prediction["rises"]
    return [
        {
            "index": k,
            "state": state,
            "measured_state": touchdowns[k]["state"],
            "rise": predicted_rises[k - 1] if 0 < k <= len(predicted_rises) else None,
            "measured_rise": rises[k - 1] if 0 < k <= len(rises) else None,
        }
        for k, state in enumerate(prediction["states"][: len(touchdowns)])
    ]


def _on_clock(clock: TrackerClock, records: list[dict]) -> list[tuple[int, dict]]:
    """Records stamped with a Unix ``time`` [s] and perhaps a ``tracker_time`` [s], at their log
    times on the tracker's clock, in the order they were recorded."""
    return [(clock.record_time(record), record) for record in records]


def _metadata(run: Run, source: Run) -> dict[str, str]:
    results = source.results
    values = {
        "run_id": run.id,
        "kind": run.kind,
        "status": run.status,
        "created_at": utc(run.created_at).isoformat(),
        "recorded_at": utc(source.created_at).isoformat(),
        "source_run_id": source.id if source is not run else None,
        "code_version": run.code_version,
        "model": run.model,
        "controls": run.controls,
        "jumps": run.jumps,
        "tags": list(run.tags),
        "calibration": results.get("calibration"),
        "closed_loop": results.get("closed_loop"),
        "end_reason": results.get("end_reason"),
        "disarm": results.get("disarm"),
        "tracker": results.get("tracker"),
        "prediction_model": _prediction_model(run.results.get("prediction")),
        "time_convention": TIME_CONVENTION,
    }
    return metadata_text(values)


def _prediction_model(prediction: dict | None) -> str | None:
    """Which model made the run's prediction, for people (None: it has none)."""
    if prediction is None:
        return None
    world = prediction.get("world")  # absent: parallel walls (backend.services.run_prediction)
    if world is None:
        return "the Poincaré map between parallel walls"
    return f"the model's climb in world {world['id']} ({world['name']})"
