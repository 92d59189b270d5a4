"""Request and response bodies of the service, a module per resource. Ranges are explicit, so bad
input is a 422 naming the field; every response has a model (the OpenAPI document lists them).

Each resource is a ladder: a ``…Base`` of what its requests and records share, ``…Create`` and
``…Update`` requests (strict: unknown fields, NaN and infinities refused), the ``…Out`` a client
reads (not held to today's input ranges, so older records still read) and a ``…Page`` of them.
"""

from backend.schemas.calibrations import CalibrationCreate, CalibrationList, CalibrationOut
from backend.schemas.common import (
    MAX_ID,
    MAX_JUMPS,
    MAX_LEVELS,
    MAX_PATH_SAMPLES,
    MAX_TRIALS,
    Health,
    Label,
    LegIn,
    ModelIn,
    Page,
    Psi0Deg,
    RecordRef,
    StateIn,
    Strict,
    TokenAccepted,
    Zeta0,
    finite_or_none,
)
from backend.schemas.experiments import (
    ExperimentBase,
    ExperimentCreate,
    ExperimentOut,
    ExperimentPage,
    ExperimentUpdate,
)
from backend.schemas.jobs import (
    JOB_KINDS,
    WORK_BUDGET_JUMPS,
    BasinJobCreate,
    GaitSearchJobCreate,
    JobCreate,
    JobOut,
    JobPage,
    JobResults,
    JobState,
    MJTFJobCreate,
    MJTFLevelOut,
    NoiseIn,
    SweepJobCreate,
)
from backend.schemas.robot import ClosedLoopIn, RobotConnect, RobotRunCreate
from backend.schemas.runs import (
    RunAggregate,
    RunBase,
    RunComparison,
    RunCreate,
    RunDetail,
    RunGroup,
    RunKind,
    RunOut,
    RunPage,
    RunStatus,
    RunTrajectory,
    RunUpdate,
    Stats,
)
from backend.schemas.sim import FixedPointIn, MapIn, TrajectoryIn
from backend.schemas.view import VIEWER_ID_PATTERN, ViewerId, ViewOut, ViewReplay

__all__ = [
    "JOB_KINDS", "MAX_ID", "MAX_JUMPS", "MAX_LEVELS", "MAX_PATH_SAMPLES", "MAX_TRIALS", "VIEWER_ID_PATTERN",
    "WORK_BUDGET_JUMPS",
    "BasinJobCreate", "CalibrationCreate", "CalibrationList", "CalibrationOut", "ClosedLoopIn", "ExperimentBase",
    "ExperimentCreate", "ExperimentOut", "ExperimentPage",
    "ExperimentUpdate", "FixedPointIn", "GaitSearchJobCreate", "Health", "JobCreate", "JobOut", "JobPage", "JobResults",
    "JobState", "Label", "LegIn", "MJTFJobCreate", "MJTFLevelOut", "MapIn", "ModelIn", "NoiseIn", "Page", "Psi0Deg",
    "RecordRef", "RobotConnect", "RobotRunCreate", "RunAggregate", "RunBase", "RunComparison", "RunCreate",
    "RunDetail", "RunGroup", "RunKind", "RunOut", "RunPage", "RunStatus", "RunTrajectory", "RunUpdate", "StateIn",
    "Stats", "Strict", "SweepJobCreate", "TokenAccepted", "TrajectoryIn", "ViewOut", "ViewReplay", "ViewerId",
    "Zeta0",
    "finite_or_none",
]  # fmt: skip
