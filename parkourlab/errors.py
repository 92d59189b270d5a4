"""What the client raises: one exception type per thing a script may want to catch.

Every answer of the service that is not a success becomes an :class:`ApiError` (or the subclass
for its status) carrying the HTTP ``status``, the API's ``detail`` as it came, and ``errors``: a
list of ``{"field", "message"}``, one per problem the service named. A 422's fields are the
request's own names (``controls[0].zeta0``, ``limit``), its messages the API's, with the bound
it broke (``Input should be less than 1``) and the value sent::

    >>> error = error_for(422, {"detail": [{"loc": ["body", "controls", 0, "zeta0"],
    ...     "msg": "Input should be less than 1", "type": "less_than", "input": 1.2}]}, "POST /api/v1/runs")
    >>> type(error).__name__, error.errors[0]["field"]
    ('InvalidRequest', 'controls[0].zeta0')
    >>> str(error)
    'POST /api/v1/runs: 422 invalid request: controls[0].zeta0: Input should be less than 1 (got 1.2)'
"""

from __future__ import annotations

import json
from typing import Any, TypedDict


class FieldError(TypedDict):
    """One problem the service named: the field (``""`` when it names none) and its message."""

    field: str
    message: str


class ParkourError(Exception):
    """Base of every error this client raises."""


class ServiceUnreachable(ParkourError, ConnectionError):
    """No connection to the service: refused, no such host, timed out. ``url`` is the service's."""

    def __init__(self, url: str, reason: str) -> None:
        self.url, self.reason = url, reason
        super().__init__(f"cannot reach the ParkourLab service at {url}: {reason} (is `parkour serve` running there?)")


class ApiError(ParkourError):
    """The service answered with an error status.

    Attributes: ``status`` (the HTTP status), ``detail`` (the API's ``detail`` as it came: a
    string, or a 422's list), ``errors`` (:class:`FieldError` list), ``request`` (``"METHOD
    path"`` of the call)."""

    def __init__(self, status: int, detail: Any, errors: list[FieldError], request: str = "") -> None:
        self.status, self.detail, self.errors, self.request = status, detail, errors, request
        super().__init__(self._message())

    def _message(self) -> str:
        what = "; ".join(f"{e['field']}: {e['message']}" if e["field"] else e["message"] for e in self.errors)
        head = f"{self.request}: " if self.request else ""
        return f"{head}{self.status} {self.reason}: {what}"

    @property
    def reason(self) -> str:
        """A few words for the status."""
        return _REASONS.get(self.status, "error")


class Unauthorized(ApiError):
    """401: a change without the service's token, or with a wrong one (``token=``,
    ``$PARKOUR_API_TOKEN``, or the data directory's ``api_token``)."""


class NotFound(ApiError):
    """404: no such run, job, experiment, calibration or path."""


class Conflict(ApiError):
    """409: the request clashes with what is stored (e.g. deleting an experiment that still has runs)."""


class QueueFull(ApiError):
    """429: the job queue holds its budget of work, or this client its share of it; the message
    says what is queued. Wait for jobs to finish (or cancel some) and submit again."""


class ServiceUnavailable(ApiError):
    """503: the service could not do it now, and says why in its message — its workers busy, or a
    computation that passed the service's own time limit and was stopped. Try again shortly
    (:meth:`parkourlab.Client.wait_ready` waits for a service that has just started)."""


class InvalidRequest(ApiError, ValueError):
    """422: a field out of its range or of the wrong type; ``errors`` names each field and the
    API's message, with the bound it broke."""


class JobFailed(ParkourError):
    """A job ended ``failed`` or ``cancelled``; ``job`` is its last state (``job["error"]`` says why)."""

    def __init__(self, job: dict[str, Any]) -> None:
        self.job = job
        why = f": {job['error']}" if job.get("error") else ""
        super().__init__(f"job {job['id']} ({job['kind']}) ended {job['state']}{why}")


class NotReady(ParkourError, TimeoutError):
    """:meth:`parkourlab.Client.wait_ready` ran out of time; ``health`` is the last answer (None if
    the service never answered), ``timeout`` the seconds waited."""

    def __init__(self, url: str, health: dict[str, Any] | None, timeout: float) -> None:
        self.url, self.health, self.timeout = url, health, timeout
        if health is None:
            what = "it did not answer"
        else:
            what = f"still {health['status']} ({', '.join(health.get('warming') or ()) or 'nothing named'})"
        super().__init__(f"the ParkourLab service at {url} was not ready after {timeout:g} s: {what}")


class JobTimeout(ParkourError, TimeoutError):
    """:meth:`parkourlab.Client.wait` ran out of time; ``job`` is the last state seen (it goes on
    running on the service: cancel it, or wait again)."""

    def __init__(self, job: dict[str, Any], timeout: float) -> None:
        self.job, self.timeout = job, timeout
        super().__init__(
            f"job {job['id']} ({job['kind']}) still {job['state']} after {timeout:g} s "
            f"({job['completed']} of {job['total']} done)"
        )


_REASONS = {
    400: "bad request",
    401: "unauthorized",
    404: "not found",
    409: "conflict",
    413: "request too large",
    422: "invalid request",
    429: "job queue full",
    500: "service error",
    503: "service unavailable",
    507: "storage full",
}
_CLASSES: dict[int, type[ApiError]] = {
    401: Unauthorized, 404: NotFound, 409: Conflict, 422: InvalidRequest, 429: QueueFull, 503: ServiceUnavailable,
}  # fmt: skip
_LOCATIONS = ("body", "query", "path", "header")


def error_for(status: int, body: Any, request: str = "") -> ApiError:
    """The exception for an error answer: ``status`` and its decoded JSON ``body`` (or its text)."""
    detail = body.get("detail", body) if isinstance(body, dict) else body
    return _CLASSES.get(status, ApiError)(status, detail, field_errors(detail), request)


def field_errors(detail: Any) -> list[FieldError]:
    """The API's ``detail`` as :class:`FieldError` s: a 422's list item by item, anything else one
    message without a field."""
    if not isinstance(detail, list):
        return [FieldError(field="", message=detail if isinstance(detail, str) else json.dumps(detail))]
    errors = []
    for item in detail:
        if not isinstance(item, dict):
            errors.append(FieldError(field="", message=str(item)))
            continue
        field = field_name(item.get("loc", []))
        message = str(item.get("msg", ""))
        message = message.removeprefix(f"{field}: ") if field else message  # a model error names it already
        if "input" in item and item["input"] is not None and not isinstance(item["input"], dict | list):
            message += f" (got {item['input']!r})" if isinstance(item["input"], str) else f" (got {item['input']})"
        errors.append(FieldError(field=field, message=message))
    return errors


def field_name(loc: list[Any]) -> str:
    """A 422's ``loc`` as the request spells it: ``["body", "controls", 0, "zeta0"]`` →
    ``controls[0].zeta0``, ``["query", "limit"]`` → ``limit``."""
    parts = list(loc[1:] if loc and loc[0] in _LOCATIONS else loc)
    name = ""
    for part in parts:
        name += f"[{part}]" if isinstance(part, int) else (f".{part}" if name else str(part))
    return name
