"""What a live run shows everyone but its control loop, immutable (:mod:`backend.robot.live_run`
writes them): :class:`RunSnapshot`, the run as it is now (the panel's status, the live 3D view),
and :class:`Record`, one thing the run recorded, for its journal."""

from __future__ import annotations

from dataclasses import dataclass

from backend.robot.messages import Leg
from backend.robot.touchdown import Touchdown
from sim_core.model.controls import LegControl

# The commands a status carries, newest last: a panel polling at 10 a second sees each of a run's
# commands (a run's start sends two at once; a law one a touchdown) and the status stays small.
RECENT_COMMANDS = 4


@dataclass(frozen=True)
class Record:
    """One thing the run recorded, for its journal: ``kind`` is ``touchdown`` (``value`` is the
    :class:`Touchdown` and the :class:`LegControl` it was made with), ``command``, ``telemetry`` or
    ``tracker_gap`` (a dict); ``value`` is never changed after it is made. A command or telemetry has
    ``time`` (Unix [s]) and ``tracker_time`` (of the run's newest frame then, or None), which places
    it in a recording (:mod:`backend.services.mcap_clock`)."""

    kind: str
    value: object


@dataclass(frozen=True)
class RunSnapshot:
    """What a live run is now, immutable: read it from any thread, as often as you like."""

    run_id: int | None  # the stored run's id (it is stored when it starts)
    started: float  # time.time()
    jumps: int  # asked for
    max_seconds: float
    target_m: float | None = None  # closed loop: the height held [m]
    active: bool = True
    touchdowns: tuple[Touchdown, ...] = ()
    touchdown_controls: tuple[LegControl, ...] = ()  # the controls each detected touchdown was made with
    commanded: tuple[tuple[Leg, LegControl], ...] = ()  # what each leg is commanded now
    commands: int = 0  # sent so far
    end_reason: str | None = None
    disarm: str | None = None  # how the ending left the robot: "disarmed", "estopped" or why unconfirmed
    started_by: str | None = None  # who started it, as other panels are told
    first_pose: int = 0  # the tracker's index of the run's first frame (its trail starts there)
    tracker_gaps: tuple[dict, ...] = ()  # stretches without a pose past the run's tracker timeout
    robot_faults: tuple[str, ...] = ()  # the robot's faults in its last telemetry at the end
    world_id: int | None = None  # the stored world it climbs (None: the parallel walls)
    plan_job_id: int | None = None  # the plan job it follows (None: none)
    recent_commands: tuple[dict, ...] = ()  # the newest commands sent (plain JSON), oldest first

    def command_for(self, leg: Leg) -> LegControl | None:
        return dict(self.commanded).get(leg)

    def to_status(self) -> dict:
        return {
            "id": self.run_id,
            "active": self.active,
            "started": self.started,
            "started_by": self.started_by,
            "touchdowns": len(self.touchdowns),
            "jumps": self.jumps,
            "max_seconds": self.max_seconds,
            "target_m": self.target_m,
            "commands": self.commands,
            "end_reason": self.end_reason,
            "disarm": self.disarm,
            "stored_run_id": self.run_id,
            "tracker_gaps": len(self.tracker_gaps),
            "longest_tracker_gap_ms": max((gap["ms"] for gap in self.tracker_gaps), default=None),
            "robot_faults": list(self.robot_faults),
            "world_id": self.world_id,
            "plan_job_id": self.plan_job_id,
            "recent_commands": list(self.recent_commands),
        }
