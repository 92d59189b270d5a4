"""Runs: what a client sends to simulate and store one, edits of its labels, and what comes back
(a listed run, a run in full, a page, a comparison, an aggregate, a sampled path)."""

from __future__ import annotations

import datetime
import enum
import math
from typing import Annotated, Literal

from pydantic import BaseModel, Field, ValidationInfo, field_validator, model_validator

from backend.schemas.common import (
    MAX_JUMPS,
    MAX_PATH_SAMPLES,
    LegIn,
    ModelIn,
    Notes,
    Page,
    RecordRef,
    StateIn,
    Strict,
    Tags,
)

Jumps = Annotated[int, Field(ge=1, le=MAX_JUMPS)]


class RunKind(enum.StrEnum):
    SIM = "sim"  # simulated by the service
    ROBOT = "robot"  # a live run on the robot
    REPLAY = "replay"  # a robot run's frames analysed again


class RunStatus(enum.StrEnum):
    DONE = "done"  # a physical failure (the robot fell) is still a run done
    FAILED = "failed"  # it could not be carried out
    RUNNING = "running"  # a live robot run, stored from its start
    INTERRUPTED = "interrupted"  # a live run the service died during, kept to its last journal entry


class RunLoop(enum.StrEnum):
    OPEN = "open"  # the controls as given (every simulation)
    CLOSED = "closed"  # a robot run holding a height: a controller sets zeta0 after each touchdown


class RunBase(BaseModel):
    """What a run is asked for with and keeps: its experiment, length and labels."""

    experiment_id: RecordRef | None = None
    world_id: RecordRef | None = Field(
        None, description="the stored world it climbs (GET /api/v1/worlds); none: parallel walls"
    )
    jumps: Jumps = 20
    tags: Tags = []


class RunCreate(RunBase, Strict):
    """Simulate a run and store it: the model, each leg's controls, the first section state."""

    model: ModelIn = ModelIn()
    controls: Annotated[list[LegIn], Field(min_length=1, max_length=16)]
    start: StateIn
    trajectory_rate: Annotated[float, Field(gt=0.0, le=1000.0)] | None = Field(
        None,
        description=f"also store the sampled path, samples per sqrt(l0/g); rate x jumps at most {MAX_PATH_SAMPLES:,}",
        json_schema_extra={"x-max-rate-times-jumps": MAX_PATH_SAMPLES},  # the panel thins a long run's path by it
    )
    fixed_point: bool = Field(False, description="also find the gait near the start state and store its eigenvalues")

    @model_validator(mode="after")
    def _gaits_are_parallel_walls(self) -> RunCreate:
        if self.fixed_point and self.world_id is not None:  # a gait is a fixed point of parallel walls' map
            raise ValueError("fixed_point: gaits are found between parallel walls, not in a world (world_id)")
        return self

    @field_validator("trajectory_rate")
    @classmethod
    def _bounded_path(cls, rate: float | None, info: ValidationInfo) -> float | None:
        # A jump lasts about 1.5 time units: this caps a stored path near 150,000 samples. Said
        # in the asker's terms: the path's samples, and the jumps (or the rate) that fit.
        jumps = info.data.get("jumps")
        if rate is None or jumps is None or rate * jumps <= MAX_PATH_SAMPLES:
            return rate
        raise ValueError(
            f"a path of {jumps:,} jumps at {rate:g} samples per sqrt(l0/g) would be about {1.5 * rate * jumps:,.0f}"
            f" samples, more than a run keeps (rate x jumps at most {MAX_PATH_SAMPLES:,}): at this rate a path is"
            f" kept for up to {math.floor(MAX_PATH_SAMPLES / rate):,} jumps; for {jumps:,} jumps, a rate of at most"
            f" {math.floor(MAX_PATH_SAMPLES / jumps * 1000) / 1000:g}, or no trajectory_rate (the run without its path)"
        )


class RunUpdate(Strict):
    """Runs are records of what happened: only their labels and notes change. Fields left out stay."""

    tags: Tags | None = None
    notes: Notes | None = None


class RunOut(RunBase):
    """A run as listed: everything but its results and path (``has_trajectory`` says if it has one).
    ``model`` is the nondimensional parameters, ``controls`` ``[[psi0_deg, zeta0], …]`` per leg,
    ``start_state`` ``[xdot, ydot]``, ``climb`` the total height gain [l0]."""

    # Outputs are not held to today's input ranges: a run stored under older limits still reads.
    id: int
    experiment_id: int | None
    jumps: int
    kind: RunKind
    status: RunStatus
    created_at: datetime.datetime
    duration_s: float
    code_version: str
    model: dict
    controls: list
    start_state: list
    jumps_completed: int
    failure_code: str | None
    climb: float
    tags: list[str]
    notes: str
    has_trajectory: bool
    end_reason: str | None = Field(
        None, description='how a robot run ended, as it recorded it: "jumps done", "stopped", "time limit", "e-stop", '
        '"link lost", "fell: …", "robot restarted: …", "robot disarmed itself: …", "tracker silent: …", '
        '"tracker lost the body: …", "error: …", "interrupted: …" (before 2026-12: "robot disarmed (fell or '
        'timed out)"); null for simulations',
    )  # fmt: skip
    loop: RunLoop = Field(RunLoop.OPEN, description="closed: a robot run holding a height (a replay: as its run)")
    controller: str | None = Field(None, description="the closed loop's law (pid, lqr, ...); null when open")
    target: float | None = Field(None, description="the height a closed loop held [m]; null when open")
    touchdowns: int | None = Field(
        None, description="robot and replay runs: the touchdowns recorded, which is what their jumps ask for "
        "(jumps_completed counts the jumps between them, one fewer); null for simulations",
    )  # fmt: skip
    created_by: str | None = Field(
        None, description="who made it (the token's person); null for runs stored before people had names"
    )
    notes_by: str | None = Field(None, description="who last wrote its notes or tags; null if nobody has")


class RunDetail(RunOut):
    """A run in full: with its results (section states, rises, failure, a fixed point if asked)."""

    results: dict


RunPage = Page[RunOut]


class RunComparison(BaseModel):
    """Runs side by side as flat records (``model.alpha``, ``leg0.zeta0`` …)."""

    fields: list[str]
    differing: list[str] = Field(description="the fields whose values differ between the runs")
    runs: list[dict[str, str | float | int | None]]


class Stats(BaseModel):
    mean: float
    std: float = Field(description="population standard deviation over the group")
    min: float
    max: float
    ci95_low: float | None = Field(
        None, description="95% confidence interval of the mean, lower end (Student's t on the sample "
        "standard deviation); null for fewer than two runs",
    )  # fmt: skip
    ci95_high: float | None = Field(None, description="95% confidence interval of the mean, upper end")


class RunGroup(BaseModel):
    key: str | float | int | None = Field(description="the group's value; a bin's centre when binned")
    runs: int
    low: float | None = Field(None, description="binned: the bin's lower edge")
    high: float | None = Field(None, description="binned: the bin's upper edge (the last bin includes it)")
    climb: Stats
    jumps_completed: Stats


class RunAggregate(BaseModel):
    by: str
    bins: int | None
    groups: list[RunGroup]


class RunTrajectory(BaseModel):
    """A run's sampled path, column by column. A simulated run's (time, x, y, foot_x, foot_y, psi,
    zeta, phase, jump) is ``nondimensional``; a robot or replay run's is the tracker's frames
    (time, x, y, pitch) in ``SI`` units. ``column_units`` names each column's unit."""

    units: Literal["nondimensional", "SI"]
    column_units: dict[str, str]
    columns: dict[str, list[float | int]]
