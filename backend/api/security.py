"""Who may change what, and what every request is held to before a route sees it.

Mutating calls carry ``Authorization: Bearer <token>``: the service's own token (``api_token`` in
the data directory, :mod:`backend.api.token_file`) or a person's (``parkour token add NAME``,
:mod:`backend.store.people`); a person's read-only token reads but changes nothing (403). Reads are
open on a service that listens on the loopback only; one that listens beyond this machine asks a
token of every request (its health check and the e-stop excepted). The robot's e-stop is open to anyone
(stopping is always allowed: docs/service.md). :func:`install` puts four ASGI middlewares in front
of the routes, outermost first:

- :class:`SecurityHeaders`: a Content-Security-Policy without inline script, ``nosniff``,
  ``no-referrer``, framing by the service's own origin only — on every response;
- :class:`HostAllowList`: a Host header not on the allow-list (the loopback names and the ones
  the settings add) is a 400, so a DNS-rebinding page cannot talk to the service; a WebSocket
  whose Origin is not an allowed host (http or https, any port) is refused;
- :class:`TokenFirst`: finds who the request comes from (:mod:`backend.api.identity`); a change
  without a token that may make it is a 401 (403) before a byte of its body is read;
- :class:`BodyLimit`: a body is counted as it arrives, chunked or not, and over the limit the
  service answers 413 without reading the rest.

Each refusal is JSON and closes the connection (the body it did not read goes with it).
"""

from __future__ import annotations

import re
from collections.abc import Iterable
from typing import Annotated
from urllib.parse import urlsplit

from fastapi import Depends, FastAPI, HTTPException, Request, status
from fastapi.responses import JSONResponse
from fastapi.routing import APIRoute, RouteContext, iter_route_contexts
from fastapi.security import HTTPAuthorizationCredentials, HTTPBearer
from starlette.datastructures import Headers, MutableHeaders
from starlette.routing import Match
from starlette.types import ASGIApp, Receive, Scope, Send

from backend.api.identity import person_of
from backend.settings import Settings, host_name

bearer = HTTPBearer(auto_error=False)


async def require_token(
    request: Request, credentials: Annotated[HTTPAuthorizationCredentials | None, Depends(bearer)]
) -> None:
    """Mutating calls carry ``Authorization: Bearer <token>`` of someone who may change things.

    :class:`TokenFirst` has already refused a request without it before its body was read; as a
    dependency it also puts the scheme on the route in OpenAPI (``credentials``), and
    :class:`TokenFirst` asks the token of exactly the routes that declare it."""
    person = person_of(request)
    if person is None:
        raise HTTPException(status.HTTP_401_UNAUTHORIZED, TOKEN_REQUIRED, headers={"WWW-Authenticate": "Bearer"})
    if not person.may_change:
        raise HTTPException(status.HTTP_403_FORBIDDEN, read_only(person.name))


MUTATING = frozenset({"POST", "PUT", "PATCH", "DELETE"})
TOKEN_REQUIRED = "a valid bearer token is required for changes (see api_token in the data directory)"
READ_TOKEN_REQUIRED = (
    "a valid bearer token is required: this service listens beyond its own machine, so reads need one too "
    "(parkour token add NAME --read-only makes one)"
)
WS_REFUSED = "a valid bearer token is required (sign in first)"
# Open to anyone wherever the service listens: stopping the robot, and what a container's health check asks.
OPEN_ANYWHERE = frozenset({"/api/v1/robot/estop", "/api/v1/health"})
HOST_REFUSED = "host not allowed: the Host header must name this service (PARKOUR_ALLOWED_HOSTS adds names)"
# A Host header (or an Origin's authority): a name or IPv4 address, or a bracketed IPv6 one; a port.
_AUTHORITY = re.compile(r"(?P<host>\[[0-9A-Fa-f:.]+\]|[A-Za-z0-9_.-]+)(?::(?P<port>[0-9]{1,5}))?")


def read_only(name: str) -> str:
    return f"{name}'s token is read-only: changes need a token with write access (parkour token add NAME)"


def open_changes(routes) -> list[RouteContext]:
    """The mutating API routes that do not declare ``require_token`` (as FastAPI includes them:
    its routers are included lazily, so ``app.routes`` lists routers, not their routes)."""
    return [
        route
        for route in iter_route_contexts(routes)
        if isinstance(route.original_route, APIRoute)
        and route.methods & MUTATING
        and not any(dependency.call is require_token for dependency in route.dependant.dependencies)
    ]


# Hosts and Origins --------------------------------------------------------------------------------
def _authority(value: str | None) -> re.Match | None:
    return None if value is None else _AUTHORITY.fullmatch(value)


def host_allowed(host_header: str | None, allowed: Iterable[str]) -> bool:
    """Whether a Host header (``name``, ``name:port``, ``[v6]:port``) names an allowed host."""
    match = _authority(host_header)
    return match is not None and host_name(match["host"]) in allowed


def origin_allowed(origin: str, allowed: Iterable[str]) -> bool:
    """Whether a browser's ``Origin`` is an allowed host over http or https, on any port: the
    panel's own origin, and the 3D view's (the same host, its own port). ``null`` is not."""
    parts = urlsplit(origin)
    return parts.scheme in ("http", "https") and not parts.path and host_allowed(parts.netloc, allowed)


# The responses' headers ---------------------------------------------------------------------------
def content_security_policy(scheme: str, host_header: str | None) -> str:
    """The policy for the service's pages: scripts and styles from the service itself (no inline
    script; inline styles, which Plotly sets, allowed), images also from data: and blob: URLs (Plotly's
    downloads), the live websocket of this host and port, the 3D view framed from any port of
    this host (viser moves to the next free port), and only this origin may frame the service."""
    match = _authority(host_header)
    connect, frames = "connect-src 'self'", "frame-src 'self'"
    if match is not None:  # a malformed Host gets the plain policy (its 400 comes next)
        ws = "wss" if scheme == "https" else "ws"
        connect += f" {ws}://{match[0]}"
        frames += f" {'https' if scheme == 'https' else 'http'}://{match['host']}:*"
    return "; ".join(
        [
            "default-src 'self'",
            "script-src 'self'",
            "style-src 'self' 'unsafe-inline'",
            "img-src 'self' data: blob:",
            "font-src 'self' data:",
            connect,
            frames,
            "frame-ancestors 'self'",
            "object-src 'none'",
            "base-uri 'self'",
            "form-action 'self'",
        ]
    )


def security_headers(scope: Scope) -> dict[str, str]:
    """The headers every response of the service carries."""
    host = Headers(scope=scope).get("host")
    return {
        "Content-Security-Policy": content_security_policy(scope.get("scheme", "http"), host),
        "X-Content-Type-Options": "nosniff",
        "Referrer-Policy": "no-referrer",
        "X-Frame-Options": "SAMEORIGIN",  # frame-ancestors' predecessor, for older browsers
    }


async def _refuse(scope: Scope, receive: Receive, send: Send, code: int, detail: str, **headers: str) -> None:
    """Answer ``code`` with ``{"detail": ...}`` and close the connection: a body left unread goes with it."""
    extra = {"Connection": "close"} | {name.replace("_", "-"): value for name, value in headers.items()}
    await JSONResponse({"detail": detail}, status_code=code, headers=extra)(scope, receive, send)


# The middlewares ----------------------------------------------------------------------------------
class SecurityHeaders:
    """Adds :func:`security_headers` to every HTTP response that does not set them itself."""

    def __init__(self, app: ASGIApp) -> None:
        self.app = app

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        extra = security_headers(scope)

        async def send_with_headers(message) -> None:
            if message["type"] == "http.response.start":
                headers = MutableHeaders(scope=message)
                for name, value in extra.items():
                    headers.setdefault(name, value)
            await send(message)

        await self.app(scope, receive, send_with_headers)


class HostAllowList:
    """A request whose Host is not an allowed name is a 400 (a WebSocket is closed, code 1008,
    before it is accepted: uvicorn answers its handshake 403); so is a WebSocket whose Origin
    is not an allowed host. No Origin (a client that is not a browser) is allowed."""

    def __init__(self, app: ASGIApp, allowed_hosts: Iterable[str]) -> None:
        self.app = app
        self.allowed = frozenset(host_name(host) for host in allowed_hosts)

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] not in ("http", "websocket"):
            await self.app(scope, receive, send)
            return
        headers = Headers(scope=scope)
        host_ok = host_allowed(headers.get("host"), self.allowed)
        if scope["type"] == "http":
            if host_ok:
                await self.app(scope, receive, send)
            else:
                await _refuse(scope, receive, send, status.HTTP_400_BAD_REQUEST, HOST_REFUSED)
            return
        origin = headers.get("origin")
        if host_ok and (origin is None or origin_allowed(origin, self.allowed)):
            await self.app(scope, receive, send)
        else:
            reason = "host not allowed" if not host_ok else "origin not allowed"
            await send({"type": "websocket.close", "code": status.WS_1008_POLICY_VIOLATION, "reason": reason})


class TokenFirst:
    """Finds who each request under /api/ comes from (left in its state: ``person_of``) and
    refuses, before a body is read: a change without a token that may make it (401, or 403 for a
    read-only one) — the changes open without it are the routes that do not declare
    ``require_token`` (the e-stop, the simulations), anything else, an unknown path included, needs
    it; and, where the settings say reads need a token, anything else with none but
    :data:`OPEN_ANYWHERE` — reads, websockets, the simulations (401; a websocket is closed, code
    1008, before it is accepted)."""

    def __init__(self, app: ASGIApp, service: FastAPI) -> None:
        self.app, self.service = app, service
        self._open: list[RouteContext] | None = None  # found at the first change: the routes are all in by then

    def needs_token(self, scope: Scope) -> bool:
        if scope["method"] not in MUTATING:
            return False
        if self._open is None:
            self._open = open_changes(self.service.routes)  # a route added later needs the token: fails closed
        return not any(route.matches(scope)[0] is Match.FULL for route in self._open)

    def refusal(self, scope: Scope, person) -> tuple[int, str] | None:
        if scope["type"] == "http" and self.needs_token(scope):
            if person is None:
                return status.HTTP_401_UNAUTHORIZED, TOKEN_REQUIRED
            return None if person.may_change else (status.HTTP_403_FORBIDDEN, read_only(person.name))
        reads_need_token = self.service.state.settings.reads_need_token
        if reads_need_token and person is None and scope["path"] not in OPEN_ANYWHERE:
            return status.HTTP_401_UNAUTHORIZED, READ_TOKEN_REQUIRED
        return None

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] not in ("http", "websocket") or not scope["path"].startswith("/api/"):
            await self.app(scope, receive, send)
            return
        person, by_header = self.service.state.identities.of_scope(scope)
        scope.setdefault("state", {}).update(person=person, person_by_header=by_header)
        refused = self.refusal(scope, person)
        if refused is None:
            await self.app(scope, receive, send)
        elif scope["type"] == "websocket":
            # a close's reason holds at most 123 bytes
            await send({"type": "websocket.close", "code": status.WS_1008_POLICY_VIOLATION, "reason": WS_REFUSED})
        else:
            headers = {"WWW_Authenticate": "Bearer"} if refused[0] == status.HTTP_401_UNAUTHORIZED else {}
            await _refuse(scope, receive, send, *refused, **headers)


class BodyLimit:
    """Reads a request's body before the route does, counting the bytes as they come (a declared
    Content-Length or a chunked stream alike), and answers 413 at the first chunk past
    ``max_bytes`` without reading the rest; within the limit, the route gets the body as it came.
    At most ``max_bytes`` (and one chunk) of a body is ever held."""

    def __init__(self, app: ASGIApp, max_bytes: int) -> None:
        self.app, self.max_bytes = app, max_bytes

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        headers = Headers(scope=scope) if scope["type"] == "http" else None
        if headers is None or ("content-length" not in headers and "transfer-encoding" not in headers):
            await self.app(scope, receive, send)  # not HTTP, or no body
            return
        length = headers.get("content-length")
        too_large = f"request body must be at most {self.max_bytes} bytes"
        if length is not None and not (length.isascii() and length.isdigit() and int(length) <= self.max_bytes):
            await _refuse(scope, receive, send, status.HTTP_413_CONTENT_TOO_LARGE, too_large)
            return
        body, size = [], 0
        while True:
            message = await receive()
            if message["type"] != "http.request":
                return  # the client went away: nobody to answer
            size += len(message.get("body", b""))
            if size > self.max_bytes:
                await _refuse(scope, receive, send, status.HTTP_413_CONTENT_TOO_LARGE, too_large)
                return
            body.append(message)
            if not message.get("more_body", False):
                break

        async def replay():
            return body.pop(0) if body else await receive()

        await self.app(scope, replay, send)


def install(app: FastAPI, settings: Settings) -> None:
    """The middlewares, outermost first: headers, Host/Origin, token, body limit."""
    app.add_middleware(BodyLimit, max_bytes=settings.max_request_bytes)
    app.add_middleware(TokenFirst, service=app)
    app.add_middleware(HostAllowList, allowed_hosts=settings.allowed_hosts)
    app.add_middleware(SecurityHeaders)
