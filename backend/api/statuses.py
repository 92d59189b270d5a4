"""The statuses each operation answers besides its success, written into the OpenAPI document.

FastAPI documents a route's success and its 422; the rest come from the layers every request
passes and from the services' errors (:mod:`backend.api.errors`), which FastAPI cannot see. They are
derived here, in one place, by rule — the middlewares' for every operation, the token's for the
routes that need it, a record's 404 for a path that names one — and, for what only some operations
do, from :data:`BY_OPERATION`. ``tests/backend/api/test_schema_fuzz.py`` holds the document to what
the service answers (schemathesis' status-code conformance).
"""

from __future__ import annotations

from typing import Any

from fastapi import FastAPI
from fastapi.routing import APIRoute, RouteContext, iter_route_contexts

from backend.api.security import require_token

MEANINGS = {
    400: "the Host (or a cross-site Origin) is not one this service answers to",
    401: "the bearer token is missing or wrong",
    403: "the bearer token is a read-only one: changes need write access",
    404: "no such record (the path's, or one the body names)",
    409: "the request clashes with what is stored or with the robot's state; the detail says how",
    413: "the body is over the service's limit",
    422: "a field out of range or of the wrong type; each error names the field",
    429: "the job queue is full, or this client holds its share of it; the detail says what is queued",
    503: "busy, not connected or not started: the detail says which; retry",
    507: "the disk holding the database is full: free space (delete runs) and retry",
}
EVERY = frozenset({400})
WRITES = frozenset({413, 507})
ROBOT = frozenset({409, 503})
COMPUTED = frozenset({503})  # awaited in a worker process, which may be busy or stopped
# What only some operations answer, by (method, path template).
BY_OPERATION: dict[tuple[str, str], frozenset[int]] = {
    ("POST", "/api/v1/runs"): COMPUTED | {404},
    ("GET", "/api/v1/runs"): COMPUTED,
    ("GET", "/api/v1/runs/export"): COMPUTED,
    ("GET", "/api/v1/runs/compare"): frozenset({404}),
    ("GET", "/api/v1/runs/{run_id}/export.mcap"): frozenset({409}),
    ("GET", "/api/v1/runs/{run_id}/touchdowns"): frozenset({409}),
    ("POST", "/api/v1/runs/{run_id}/replay"): frozenset({409}),
    ("DELETE", "/api/v1/experiments/{experiment_id}"): frozenset({409}),
    ("POST", "/api/v1/calibrations"): frozenset({404, 409}),
    ("POST", "/api/v1/jobs"): frozenset({404, 429}),
    ("GET", "/api/v1/robot/events"): frozenset({503}),
    ("GET", "/api/v1/auth"): frozenset({401}),
    ("POST", "/api/v1/robot/connect"): ROBOT,
    ("POST", "/api/v1/robot/disconnect"): ROBOT,
    ("POST", "/api/v1/robot/arm"): ROBOT,
    ("POST", "/api/v1/robot/disarm"): ROBOT,
    ("POST", "/api/v1/robot/reset"): ROBOT,
    ("POST", "/api/v1/robot/runs"): ROBOT | {404},
    ("POST", "/api/v1/robot/runs/stop"): ROBOT,
    ("GET", "/api/v1/view"): COMPUTED,
    ("POST", "/api/v1/view/replay"): COMPUTED | {404, 409},
    ("GET", "/api/v1/runs/{run_id}/share.html"): COMPUTED,
    ("POST", "/api/v1/sim/map"): COMPUTED,
    ("POST", "/api/v1/sim/trajectory"): COMPUTED,
    ("POST", "/api/v1/sim/fixed-point"): COMPUTED | {422},
}
_ERROR = {"type": "object", "required": ["detail"], "properties": {"detail": {}}}


def statuses_of(route: RouteContext, method: str) -> frozenset[int]:
    """The error statuses ``method`` on ``route`` answers besides FastAPI's own."""
    found = set(EVERY) | BY_OPERATION.get((method, route.path_format), frozenset())
    if method not in ("GET", "HEAD"):
        found |= WRITES
    if any(dependency.call is require_token for dependency in route.dependant.dependencies):
        found |= {401, 403}
    if "{" in route.path_format:
        found.add(404)
    return frozenset(found)


def install(app: FastAPI) -> None:
    """Make ``app.openapi()`` list every operation's error statuses (after the routes are included)."""
    build = app.openapi

    def openapi() -> dict[str, Any]:
        if app.openapi_schema is not None:
            return app.openapi_schema
        document = build()
        for route in iter_route_contexts(app.routes):  # routers are included lazily: their routes, here
            if not isinstance(route.original_route, APIRoute) or not route.original_route.include_in_schema:
                continue
            for method in route.methods:
                operation = document["paths"].get(route.path_format, {}).get(method.lower())
                if operation is None:
                    continue
                for code in sorted(statuses_of(route, method)):
                    operation["responses"].setdefault(
                        str(code),
                        {"description": MEANINGS[code], "content": {"application/json": {"schema": _ERROR}}},
                    )
        app.openapi_schema = document
        return document

    app.openapi = openapi
