"""Request and response bodies of the service. Ranges are explicit, so bad input is a 422 naming the field."""

from __future__ import annotations

import datetime
import enum
import math
from typing import Annotated, Literal

from pydantic import BaseModel, ConfigDict, Discriminator, Field, field_validator, model_validator
from pydantic import Tag as KindTag

from backend.robot.ports import check_port
from backend.robot.xbee import ROBOT_ADDRESS

Psi0Deg = Annotated[float, Field(gt=0.0, lt=90.0, description="leg angle at touchdown [degrees], in (0, 90)")]
Zeta0 = Annotated[float, Field(gt=0.0, lt=1.0, description="leg length at touchdown [l0], in (0, 1)")]
Label = Annotated[str, Field(min_length=1, max_length=64, pattern=r"^[\w.:/-]+$")]  # a tag

MAX_JUMPS = 10_000
MAX_TRIALS = 100_000
MAX_LEVELS = 100
MAX_PATH_SAMPLES = 100_000
# A job's work, in jumps at its worst (every trial to its cap, every basin point to its jump limit):
# about an hour of the job worker on the lab's machine (1.35e5-1.6e5 jumps/s measured by
# scripts/bench_job_rate.py on 2 cores). Larger jobs are refused with a 422 naming the limit.
WORK_BUDGET_JUMPS = 500_000_000
MAX_ID = 2**31 - 1  # integer keys: the smallest range among the supported databases (PostgreSQL)
RecordRef = Annotated[int, Field(ge=1, le=MAX_ID)]


class RunKind(enum.StrEnum):
    SIM = "sim"  # simulated by the service
    ROBOT = "robot"  # a live run on the robot
    REPLAY = "replay"  # a robot run's frames analysed again


class RunStatus(enum.StrEnum):
    DONE = "done"  # a physical failure (the robot fell) is still a run done
    FAILED = "failed"  # it could not be carried out
    RUNNING = "running"  # a live robot run, stored from its start
    INTERRUPTED = "interrupted"  # a live run the service died during, kept to its last journal entry


class JobState(enum.StrEnum):
    QUEUED = "queued"
    RUNNING = "running"
    CANCELLING = "cancelling"
    CANCELLED = "cancelled"
    DONE = "done"
    FAILED = "failed"


class Strict(BaseModel):
    """Every request body: unknown fields refused; NaN, ±Infinity (and 1e309, which JSON parsing
    makes infinite) refused in every float field; a string with a lone surrogate (``"\\ud800"``)
    is refused by pydantic itself (``string_unicode``) — each a 422 naming the field."""

    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)


class LegIn(Strict):
    psi0_deg: Psi0Deg
    zeta0: Zeta0


class ModelIn(Strict):
    """The ``paper`` preset with optional nondimensional overrides (docs/model.md §1)."""

    preset: Literal["paper"] = "paper"
    alpha: Annotated[float, Field(gt=0.0, le=1e4)] | None = None
    d_hat: Annotated[float, Field(gt=0.0, le=100.0)] | None = None
    c_zeta: Annotated[float, Field(ge=0.0, le=1e3)] | None = None
    c_psi: Annotated[float, Field(ge=0.0, le=1e3)] | None = None
    mu: Annotated[float, Field(gt=0.0)] | None = Field(None, description="friction coefficient; omit for the preset")


class StateIn(Strict):
    xdot: Annotated[float, Field(lt=0.0, ge=-100.0, description="section xdot [sqrt(g l0)], < 0")]
    ydot: Annotated[float, Field(ge=-100.0, le=100.0)]


class RunCreate(Strict):
    experiment_id: RecordRef | None = None
    model: ModelIn = ModelIn()
    controls: Annotated[list[LegIn], Field(min_length=1, max_length=16)]
    start: StateIn
    jumps: Annotated[int, Field(ge=1, le=MAX_JUMPS)] = 20
    trajectory_rate: Annotated[float, Field(gt=0.0, le=1000.0)] | None = Field(
        None, description="also store the sampled path, samples per sqrt(l0/g)"
    )
    tags: Annotated[list[Label], Field(max_length=32)] = []
    fixed_point: bool = Field(False, description="also find the gait near the start state and store its eigenvalues")

    @model_validator(mode="after")
    def _bounded_path(self) -> RunCreate:
        # A jump lasts about 1.5 time units: this caps a stored path near 150,000 samples.
        if self.trajectory_rate is not None and self.trajectory_rate * self.jumps > MAX_PATH_SAMPLES:
            samples = self.trajectory_rate * self.jumps
            raise ValueError(f"trajectory_rate x jumps must be at most {MAX_PATH_SAMPLES:,}, got {samples:g}")
        return self


class RunUpdate(Strict):
    """Runs are records of what happened: only their labels and notes change. Fields left out stay."""

    tags: Annotated[list[Label], Field(max_length=32)] | None = None
    notes: Annotated[str, Field(max_length=100_000)] | None = None


class RunOut(BaseModel):
    id: int
    experiment_id: int | None
    kind: RunKind
    status: RunStatus
    created_at: datetime.datetime
    duration_s: float
    code_version: str
    model: dict
    controls: list
    start_state: list
    jumps: int
    jumps_completed: int
    failure_code: str | None
    climb: float
    tags: list[str]
    notes: str
    has_trajectory: bool


class RunDetail(RunOut):
    results: dict


class Page(BaseModel):
    items: list
    next_cursor: int | None = Field(None, description="pass as ?cursor= for the next page; null at the end")


class ExperimentCreate(Strict):
    name: Annotated[str, Field(min_length=1, max_length=200)]
    description: Annotated[str, Field(max_length=10_000)] = ""
    notes: Annotated[str, Field(max_length=100_000)] = ""
    tags: Annotated[list[Label], Field(max_length=32)] = []


class ExperimentUpdate(Strict):
    name: Annotated[str, Field(min_length=1, max_length=200)] | None = None
    description: Annotated[str, Field(max_length=10_000)] | None = None
    notes: Annotated[str, Field(max_length=100_000)] | None = None
    tags: Annotated[list[Label], Field(max_length=32)] | None = None


class ExperimentOut(BaseModel):
    id: int
    name: str
    description: str
    notes: str
    tags: list[str]
    created_at: datetime.datetime
    updated_at: datetime.datetime
    runs: int


class NoiseIn(Strict):
    psi0_deg: Annotated[float, Field(ge=0.0, lt=30.0)] = 0.5
    zeta0: Annotated[float, Field(ge=0.0, lt=0.2)] = 0.003
    velocity: Annotated[float, Field(ge=0.0, lt=1.0)] = 0.01
    pitch_drift_deg: Annotated[float, Field(ge=0.0, lt=30.0)] = 0.5
    asymmetry_psi0_deg: Annotated[float, Field(gt=-30.0, lt=30.0)] = 0.0
    asymmetry_zeta0: Annotated[float, Field(gt=-0.5, lt=0.5)] = 0.0


class MJTFJobCreate(Strict):
    """Mean Jumps To Failure: ``levels`` zeta0 values x ``trials`` noisy trials each."""

    kind: Literal["mjtf"] = "mjtf"
    experiment_id: RecordRef | None = None
    model: ModelIn = ModelIn()
    psi0_deg: Psi0Deg = 30.0
    zeta0s: Annotated[list[Zeta0], Field(min_length=1, max_length=MAX_LEVELS)]
    trials: Annotated[int, Field(ge=1, le=MAX_TRIALS)] = 8
    cap: Annotated[int, Field(ge=1, le=100_000)] = 1000
    seed: Annotated[int, Field(ge=0, lt=2**63)] = 0
    noise: NoiseIn = NoiseIn()
    guess: StateIn | None = None

    @field_validator("zeta0s")
    @classmethod
    def _distinct(cls, values: list[float]) -> list[float]:
        if len(set(values)) != len(values):
            raise ValueError("zeta0 values must be distinct")
        return values

    @model_validator(mode="after")
    def _within_budget(self) -> MJTFJobCreate:
        return _within_budget(self, len(self.zeta0s) * self.trials * self.cap, "levels x trials x cap")


class SweepJobCreate(Strict):
    """An energy sweep: the gait followed over zeta0, with basin areas (``basin_grid`` 0: none)."""

    kind: Literal["sweep"]
    experiment_id: RecordRef | None = None
    model: ModelIn = ModelIn()
    psi0_deg: Psi0Deg = 30.0
    zeta0_low: Zeta0 = 0.8
    zeta0_high: Zeta0 = 0.97
    steps: Annotated[int, Field(ge=2, le=500)] = 30
    basin_grid: Annotated[int, Field(ge=0, le=200)] = 40
    basin_jumps: Annotated[int, Field(ge=1, le=1000)] = 60
    guess: StateIn | None = None

    @model_validator(mode="after")
    def _ordered(self) -> SweepJobCreate:
        if not self.zeta0_low < self.zeta0_high:
            raise ValueError(f"zeta0_low must be below zeta0_high, got {self.zeta0_low:g} >= {self.zeta0_high:g}")
        if self.basin_grid == 1:
            raise ValueError("basin_grid must be 0 (no basins) or at least 2")
        return _within_budget(
            self, self.steps * self.basin_grid**2 * self.basin_jumps, "steps x basin_grid² x basin_jumps"
        )


class BasinJobCreate(Strict):
    """The basin of attraction of a gait over a grid of section states."""

    kind: Literal["basin"]
    experiment_id: RecordRef | None = None
    model: ModelIn = ModelIn()
    controls: Annotated[list[LegIn], Field(min_length=1, max_length=16)]
    period: Annotated[int, Field(ge=1, le=16)] | None = None
    guess: StateIn | None = None
    grid: Annotated[int, Field(ge=2, le=1000)] = 100
    jumps: Annotated[int, Field(ge=1, le=1000)] = 60
    tolerance: Annotated[float, Field(gt=0.0, lt=10.0)] = 0.02

    @model_validator(mode="after")
    def _within_budget(self) -> BasinJobCreate:
        return _within_budget(self, self.grid**2 * self.jumps, "grid² x jumps")


class GaitSearchJobCreate(Strict):
    """Distinct gaits of one control schedule, from a grid of guesses."""

    kind: Literal["gaits"]
    experiment_id: RecordRef | None = None
    model: ModelIn = ModelIn()
    controls: Annotated[list[LegIn], Field(min_length=1, max_length=16)]
    period: Annotated[int, Field(ge=1, le=16)] | None = None
    grid: Annotated[int, Field(ge=1, le=20)] = 6


def _within_budget(job, jumps: int, formula: str):
    """``job`` if its worst-case work (``jumps``, counted as ``formula``) fits the budget."""
    if jumps > WORK_BUDGET_JUMPS:
        raise ValueError(
            f"the job would take up to {jumps:.3g} jumps ({formula}), over the limit of {WORK_BUDGET_JUMPS:.3g} "
            "(about an hour of the job worker); ask for less, or split it into several jobs"
        )
    return job


def _job_kind(value) -> str:
    """The job's ``kind``; MJTF when absent (the first kind, which clients may leave out)."""
    if isinstance(value, dict):
        return value.get("kind", "mjtf")
    return getattr(value, "kind", "mjtf")


JobCreate = Annotated[
    Annotated[MJTFJobCreate, KindTag("mjtf")]
    | Annotated[SweepJobCreate, KindTag("sweep")]
    | Annotated[BasinJobCreate, KindTag("basin")]
    | Annotated[GaitSearchJobCreate, KindTag("gaits")],
    Discriminator(_job_kind),
]
JOB_KINDS = {"mjtf": MJTFJobCreate, "sweep": SweepJobCreate, "basin": BasinJobCreate, "gaits": GaitSearchJobCreate}


class JobOut(BaseModel):
    id: int
    experiment_id: int | None
    kind: str
    state: JobState
    total: int
    completed: int
    progress: float
    error: str | None
    spec: dict
    created_at: datetime.datetime
    started_at: datetime.datetime | None
    finished_at: datetime.datetime | None


class MJTFLevelOut(BaseModel):
    zeta0: float
    trials: int
    mean: float
    std: float
    outcomes: dict[str, int]


class JobResults(BaseModel):
    job: JobOut
    levels: list[MJTFLevelOut] | None = Field(None, description="MJTF jobs: per energy level")
    result: dict | None = Field(None, description="other jobs: the study's result, once done")


class MapIn(Strict):
    model: ModelIn = ModelIn()
    controls: Annotated[list[LegIn], Field(min_length=1, max_length=16)]
    start: StateIn
    jumps: Annotated[int, Field(ge=1, le=1000)] = 1


class TrajectoryIn(Strict):
    model: ModelIn = ModelIn()
    controls: Annotated[list[LegIn], Field(min_length=1, max_length=16)]
    start: StateIn
    jumps: Annotated[int, Field(ge=1, le=50)] = 4
    rate: Annotated[float, Field(gt=0.0, le=500.0, description="samples per sqrt(l0/g)")] = 60.0


class FixedPointIn(Strict):
    model: ModelIn = ModelIn()
    controls: Annotated[list[LegIn], Field(min_length=1, max_length=16)]
    period: Annotated[int, Field(ge=1, le=16)] | None = None
    guess: StateIn | None = None


class RobotConnect(Strict):
    """Open the link: a pyserial URL (``/dev/ttyUSB0``, ``socket://host:port``) and the tracker's UDP port."""

    # Serial devices and ptys (symlinks followed), the virtual robot's socket, RFC 2217, a loopback:
    # never a regular file or another device (backend.robot.ports).
    url: Annotated[
        str,
        Field(max_length=200, description="a serial device or pty, socket://host:port, rfc2217://host:port, loop://"),
    ]
    robot_address: Annotated[
        str,
        Field(
            pattern=r"^(0x)?[0-9A-Fa-f]{16}$",
            description="the robot radio's 64-bit address (its XBee's SH:SL, hex); frames from any other are dropped",
        ),
    ] = f"0x{ROBOT_ADDRESS:016X}"
    baud: Annotated[int, Field(ge=1200, le=1_000_000)] = 57_600
    tracker_host: Annotated[str, Field(max_length=100, pattern=r"^[\w.:-]+$")] = "127.0.0.1"
    tracker_port: Annotated[int, Field(ge=0, le=65535)] = 9751
    calibration_origin: Annotated[list[Annotated[float, Field(ge=-1e4, le=1e4)]], Field(min_length=2, max_length=2)] = [
        0.0,
        0.0,
    ]
    calibration_angle: Annotated[float, Field(ge=-3.2, le=3.2, description="camera rotation [rad]")] = 0.0
    calibration_scale: Annotated[float, Field(gt=0.0, le=1e4, description="metres per camera unit")] = 1.0
    psi0_limits_deg: Annotated[list[Psi0Deg], Field(min_length=2, max_length=2)] = [10.0, 60.0]
    zeta0_limits: Annotated[list[Zeta0], Field(min_length=2, max_length=2)] = [0.75, 0.98]

    @field_validator("url")
    @classmethod
    def _openable(cls, url: str) -> str:
        return check_port(url)


class ClosedLoopIn(Strict):
    target_m: Annotated[float, Field(gt=0.0, le=100.0, description="height to hold [m]")]
    kp: Annotated[float, Field(ge=0.0, le=10.0)] = 0.04
    ki: Annotated[float, Field(ge=0.0, le=10.0)] = 0.0
    kd: Annotated[float, Field(ge=0.0, le=10.0)] = 0.02
    zeta0_min: Zeta0 = 0.80
    zeta0_max: Zeta0 = 0.98


class RobotRunCreate(Strict):
    """A live run: the left and right legs' controls, bounded in jumps and time; optionally closed loop."""

    experiment_id: RecordRef | None = None
    controls: Annotated[list[LegIn], Field(min_length=2, max_length=2, description="[left, right]")]
    jumps: Annotated[int, Field(ge=1, le=10_000)] = 20
    max_seconds: Annotated[float, Field(gt=0.0, le=3600.0)] = 60.0
    closed_loop: ClosedLoopIn | None = None
    tags: Annotated[list[Label], Field(max_length=32)] = []


class ViewReplay(Strict):
    """Show a stored run in the 3D view, optionally with a second run as a ghost beside it."""

    run_id: RecordRef
    overlay_run_id: RecordRef | None = None


class ViewOut(BaseModel):
    available: bool
    port: int | None = None
    mode: str | None = None
    run_id: int | None = None
    updates_per_s: float | None = None
    clients: int | None = None
    reason: str | None = None
    starting: bool = False  # not available yet: it is being built in the background


def finite_or_none(value: float) -> float | None:
    return value if math.isfinite(value) else None
