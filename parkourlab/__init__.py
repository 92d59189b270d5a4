"""ParkourLab's Python client: batch scripts drive the service's REST API with it, as MLflow's
``MlflowClient`` or ``wandb.Api`` do theirs (README, "Batch scripts: the Python client").

It speaks HTTP only and imports none of the project's other packages (sim_core, backend …;
an import-linter contract holds it), so a script on another machine needs only this package,
httpx and rich — and pandas for DataFrames.
"""

from parkourlab.client import Client
from parkourlab.errors import (
    ApiError,
    Conflict,
    FieldError,
    InvalidRequest,
    JobFailed,
    JobTimeout,
    NotFound,
    NotReady,
    ParkourError,
    QueueFull,
    ServiceUnavailable,
    ServiceUnreachable,
    Unauthorized,
)

__all__ = [
    "ApiError",
    "Client",
    "Conflict",
    "FieldError",
    "InvalidRequest",
    "JobFailed",
    "JobTimeout",
    "NotFound",
    "NotReady",
    "ParkourError",
    "QueueFull",
    "ServiceUnavailable",
    "ServiceUnreachable",
    "Unauthorized",
]
