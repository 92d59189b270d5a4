"""One table from the exceptions services raise to the HTTP status a client gets.

Errors a client can fix come back as 4xx JSON with the field and the allowed range; nothing
returns a traceback.
"""

from __future__ import annotations

from fastapi import FastAPI, status
from fastapi.responses import JSONResponse

from backend.robot.link import LinkError
from backend.services import records
from backend.services.robot import RobotUnavailable
from backend.store.database import StorageFull
from sim_core import FixedPointNotFound, ParameterError

STATUS_OF: dict[type[Exception], tuple[int, str]] = {
    records.NotFound: (status.HTTP_404_NOT_FOUND, "{}"),
    records.Conflict: (status.HTTP_409_CONFLICT, "{}"),
    RobotUnavailable: (status.HTTP_409_CONFLICT, "{}"),
    LinkError: (status.HTTP_503_SERVICE_UNAVAILABLE, "robot link: {}"),
    FixedPointNotFound: (status.HTTP_422_UNPROCESSABLE_CONTENT, "{}"),
    StorageFull: (status.HTTP_507_INSUFFICIENT_STORAGE, "{}"),  # any write, any database (store/database.py)
}


def install(app: FastAPI) -> None:
    """Map every service exception to its status (``STATUS_OF``); a ParameterError names its field."""
    for kind, (code, template) in STATUS_OF.items():

        async def handler(_request, error, code=code, template=template):
            return JSONResponse({"detail": template.format(error)}, status_code=code)

        app.add_exception_handler(kind, handler)

    async def bad_parameter(_request, error: ParameterError):
        body = {"detail": [{"loc": ["body", error.field], "msg": str(error), "type": "value_error"}]}
        return JSONResponse(body, status_code=status.HTTP_422_UNPROCESSABLE_CONTENT)

    app.add_exception_handler(ParameterError, bad_parameter)
