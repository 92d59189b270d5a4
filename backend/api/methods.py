"""Which methods a path answers, so that a wrong method is a 405 that says them all.

Starlette answers a method a path does not take with a 405 whose ``Allow`` names the methods of
the first route that matched the path only — ``OPTIONS /runs/1`` said ``GET`` though the path
also takes PATCH and DELETE — and a method that a literal path does not take but a sibling with a
parameter does (``PATCH /runs/aggregate``) reaches that sibling, whose id cannot be read: a 422
about ``run_id`` for a path that names no run. Here the first becomes a 405 listing every method
of every route the path matches, the second a 405 listing the literal path's own.
"""

from __future__ import annotations

from collections.abc import Iterator

from fastapi import Request
from fastapi.responses import JSONResponse
from fastapi.routing import iter_route_contexts

NOT_ALLOWED = "method {method} not allowed on {path}; it takes {allowed}"


def _routes(request: Request) -> Iterator[tuple[str, object, set[str]]]:
    """``(path format, path regex, methods)`` of every route with methods (FastAPI includes routers
    lazily: their routes are found through :func:`fastapi.routing.iter_route_contexts`)."""
    for route in iter_route_contexts(request.app.routes):
        regex, methods = getattr(route, "path_regex", None), route.methods
        if regex is not None and methods and route.path_format:
            yield route.path_format, regex, methods


def allowed_methods(request: Request) -> set[str]:
    """Every method the request's path takes, over every route whose path matches it."""
    path = request.url.path
    return {method for _, regex, methods in _routes(request) if regex.match(path) for method in methods}


def literal_methods(request: Request) -> set[str]:
    """The methods of the routes whose path is the request's path as written (no parameters)."""
    path = request.url.path
    return {method for form, _, methods in _routes(request) if "{" not in form and form == path for method in methods}


def not_allowed(request: Request, methods: set[str]) -> JSONResponse:
    """A 405 for the request, ``Allow`` listing ``methods``."""
    allowed = ", ".join(sorted(methods))
    detail = NOT_ALLOWED.format(method=request.method, path=request.url.path, allowed=allowed)
    return JSONResponse({"detail": detail}, status_code=405, headers={"Allow": allowed})
