"""One table from the exceptions services raise to the HTTP status a client gets, and every
error as a small JSON answer.

Errors a client can fix come back as 4xx JSON with the field and the allowed range. A 422 keeps
FastAPI's ``detail[]`` shape (``loc``, ``msg``, ``type``, ``input``, ``ctx``) but quotes at most
:data:`PREVIEW_CHARS` characters of the input, whatever it was (a megabyte string, NaN, a lone
surrogate), and at most :data:`MAX_ERRORS` errors. Anything unforeseen is a JSON 500 that says
nothing of the internals; the exception goes to the log. Unknown paths (404) are JSON; a method a
path does not take is a 405 whose ``Allow`` lists every method the path takes (:mod:`backend.api.methods`).
"""

from __future__ import annotations

import json
import logging
import math

from fastapi import FastAPI, Request, status
from fastapi.exception_handlers import http_exception_handler
from fastapi.exceptions import RequestValidationError
from fastapi.responses import JSONResponse
from starlette.exceptions import HTTPException as StarletteHTTPException

from backend.api import methods, security
from backend.errors import Conflict, NotFound, QueueFull
from backend.robot.link import EstopLatched, LinkError
from backend.services.robot import RobotUnavailable
from backend.services.robot_tracker import TrackerPortInUse
from backend.store.database import StorageFull
from backend.workers.pools import ComputeBusy, ComputeFailed, ComputeTimeout
from sim_core import FixedPointNotFound, ParameterError

log = logging.getLogger("parkourlab.api")
PREVIEW_CHARS = 200  # of an input quoted back in a 422
MAX_ERRORS = 20  # listed in one 422; the rest are counted
SERVER_ERROR = "internal server error (logged by the service)"
VALUE_ERROR_PREFIX = "Value error, "  # pydantic's, before the message of a validator's ValueError

STATUS_OF: dict[type[Exception], tuple[int, str]] = {
    NotFound: (status.HTTP_404_NOT_FOUND, "{}"),
    Conflict: (status.HTTP_409_CONFLICT, "{}"),
    QueueFull: (status.HTTP_429_TOO_MANY_REQUESTS, "{}"),
    RobotUnavailable: (status.HTTP_409_CONFLICT, "{}"),
    TrackerPortInUse: (status.HTTP_409_CONFLICT, "{}"),
    EstopLatched: (status.HTTP_409_CONFLICT, "{}"),  # before LinkError, its base: the latch is no outage
    LinkError: (status.HTTP_503_SERVICE_UNAVAILABLE, "robot link: {}"),
    FixedPointNotFound: (status.HTTP_422_UNPROCESSABLE_CONTENT, "{}"),
    ComputeBusy: (status.HTTP_503_SERVICE_UNAVAILABLE, "busy: {}"),
    ComputeTimeout: (status.HTTP_503_SERVICE_UNAVAILABLE, "{}"),
    ComputeFailed: (status.HTTP_503_SERVICE_UNAVAILABLE, "{}"),
    StorageFull: (status.HTTP_507_INSUFFICIENT_STORAGE, "{}"),  # any write, any database (store/database.py)
}


def install(app: FastAPI) -> None:
    """Map every service exception to its status (``STATUS_OF``); a ParameterError names its field;
    validation errors are kept small; anything else is a logged 500."""
    for kind, (code, template) in STATUS_OF.items():

        async def handler(_request, error, code=code, template=template):
            return JSONResponse({"detail": template.format(error)}, status_code=code)

        app.add_exception_handler(kind, handler)

    async def bad_parameter(_request, error: ParameterError):
        body = {"detail": [{"loc": ["body", error.field], "msg": str(error), "type": "value_error"}]}
        return JSONResponse(body, status_code=status.HTTP_422_UNPROCESSABLE_CONTENT)

    async def invalid_request(request: Request, error: RequestValidationError):
        errors = error.errors()
        if any(entry.get("loc", ("",))[0] == "path" for entry in errors):
            literal = methods.literal_methods(request)
            if literal and request.method not in literal:  # PATCH /runs/aggregate: no run id, a wrong method
                return methods.not_allowed(request, literal)
        return JSONResponse({"detail": compact_errors(errors)}, status_code=status.HTTP_422_UNPROCESSABLE_CONTENT)

    async def server_error(request: Request, error: Exception):
        # Starlette's ServerErrorMiddleware calls this, outside the middlewares that add the headers.
        log.error("unhandled error on %s %s", request.method, request.url.path, exc_info=error)
        headers = security.security_headers(request.scope)
        return JSONResponse(
            {"detail": SERVER_ERROR}, status_code=status.HTTP_500_INTERNAL_SERVER_ERROR, headers=headers
        )

    async def http_error(request: Request, error: StarletteHTTPException):
        allowed = methods.allowed_methods(request) if error.status_code == status.HTTP_405_METHOD_NOT_ALLOWED else None
        if allowed:
            return methods.not_allowed(request, allowed)
        return await http_exception_handler(request, error)  # FastAPI's own, for every other status

    app.add_exception_handler(StarletteHTTPException, http_error)
    app.add_exception_handler(ParameterError, bad_parameter)
    app.add_exception_handler(RequestValidationError, invalid_request)
    app.add_exception_handler(Exception, server_error)


def compact_errors(errors: list[dict]) -> list[dict]:
    """Pydantic's errors as FastAPI shows them (loc, msg, type, input, ctx), each small and valid JSON."""
    shown = [_compact(error) for error in errors[:MAX_ERRORS]]
    if len(errors) > MAX_ERRORS:
        more = len(errors) - MAX_ERRORS
        shown.append({"loc": [], "msg": f"and {more} more errors", "type": "too_many_errors"})
    return shown


def _compact(error: dict) -> dict:
    out = {
        "loc": [part if isinstance(part, int) else _text(str(part), 100) for part in error.get("loc", ())],
        "msg": _text(str(error.get("msg", "")).removeprefix(VALUE_ERROR_PREFIX), 500),
        "type": _text(str(error.get("type", "")), 100),
    }
    if "input" in error:
        out["input"] = preview(error["input"])
    if error.get("ctx"):
        out["ctx"] = {_text(str(key), 100): _ctx_value(value) for key, value in error["ctx"].items()}
    return out


def preview(value) -> object:
    """``value`` itself if its JSON is valid and at most :data:`PREVIEW_CHARS` long; else its JSON
    text (non-ASCII escaped, NaN and Infinity spelled out), cut to that length with "…"."""
    try:
        strict = json.dumps(value, ensure_ascii=False, allow_nan=False)
        strict.encode("utf-8")  # a lone surrogate is no UTF-8
        if len(strict) <= PREVIEW_CHARS:
            return value
    except (TypeError, ValueError, RecursionError):  # UnicodeEncodeError is a ValueError
        pass
    try:
        text = json.dumps(value, ensure_ascii=True, default=lambda thing: f"<{type(thing).__name__}>")
    except (ValueError, RecursionError):
        text = f"<{type(value).__name__}>"
    return text if len(text) <= PREVIEW_CHARS else text[: PREVIEW_CHARS - 1] + "…"


def _ctx_value(value) -> object:
    if value is None or isinstance(value, bool | int) or (isinstance(value, float) and math.isfinite(value)):
        return value
    return _text(str(value), PREVIEW_CHARS)


def _text(text: str, limit: int) -> str:
    """``text`` valid as UTF-8 (lone surrogates escaped) and at most ``limit`` characters."""
    text = text.encode("utf-8", "backslashreplace").decode("utf-8")
    return text if len(text) <= limit else text[: limit - 1] + "…"
