"""The service itself: health, the panel's entry, local copies of Plotly and the API docs.

Static assets go gzip-compressed to a browser that takes it: Plotly (4.8 MB, 1.4 MB compressed)
from a copy compressed once, at its first request; the panel's and the docs' files through
:func:`compressed` (Starlette's GZipMiddleware around their mounts only, so no API response or
event stream is buffered or compressed).
"""

from __future__ import annotations

import functools
import gzip
import hashlib
import html
import json
from pathlib import Path

import anyio.to_thread
import fastapi_offline
import plotly
from fastapi import APIRouter, Request
from fastapi.openapi.docs import swagger_ui_default_parameters
from fastapi.responses import FileResponse, HTMLResponse, JSONResponse, RedirectResponse, Response
from starlette.middleware.gzip import GZipMiddleware
from starlette.types import ASGIApp

from backend import schemas
from backend.api.deps import Db
from backend.api.identity import READ_COOKIE, bearer_token, person_of, signed_in_by_header
from backend.services.provenance import current_code_version
from backend.store.database import ping

SWAGGER_ASSETS = Path(fastapi_offline.__file__).parent / "static"  # Swagger UI 5: reads OpenAPI 3.1
PLOTLY_JS = Path(plotly.__file__).parent / "package_data" / "plotly.min.js"  # served locally: no CDN

router = APIRouter()


@router.get("/", include_in_schema=False)
def index() -> RedirectResponse:
    return RedirectResponse("/panel/")


COMPRESS_FROM_BYTES = 1024  # smaller files go as they are: gzip saves too little on them
VARY = {"Vary": "Accept-Encoding"}  # a cache keeps the compressed and the plain answer apart


def compressed(app: ASGIApp) -> ASGIApp:
    """Static files ``app`` (a mount) answering gzip to a browser that takes it."""
    return GZipMiddleware(app, minimum_size=COMPRESS_FROM_BYTES, compresslevel=6)


def takes_gzip(accept_encoding: str | None) -> bool:
    """Whether an ``Accept-Encoding`` header takes gzip (``gzip`` or ``*``, not at q=0)."""
    for part in (accept_encoding or "").lower().split(","):
        coding, *params = (piece.strip() for piece in part.split(";"))
        if coding in ("gzip", "*"):
            quality = next((param[2:] for param in params if param.startswith("q=")), "1")
            try:
                return float(quality) > 0
            except ValueError:
                return False
    return False


@functools.cache
def _gzipped(path: Path) -> tuple[bytes, str]:
    """``path`` compressed (at gzip's best: made once, sent many times) and its ETag."""
    data = path.read_bytes()
    return gzip.compress(data, compresslevel=9, mtime=0), f'"{hashlib.sha256(data).hexdigest()[:32]}-gz"'


@router.get("/static/plotly.min.js", include_in_schema=False)
async def plotly_js(request: Request) -> Response:
    """Plotly, compressed once and kept (a request waits for that once, in a thread), or as it
    is to a client that does not take gzip."""
    if not takes_gzip(request.headers.get("accept-encoding")):
        return FileResponse(PLOTLY_JS, media_type="text/javascript", headers=VARY)
    body, etag = await anyio.to_thread.run_sync(_gzipped, PLOTLY_JS)
    headers = {**VARY, "ETag": etag, "Cache-Control": "no-cache"}  # revalidated: a 304 costs no bytes
    if etag in request.headers.get("if-none-match", ""):
        return Response(status_code=304, headers=headers)
    return Response(body, media_type="text/javascript", headers={**headers, "Content-Encoding": "gzip"})


# Swagger UI's page with its start-up script in a file of its own, not inline (FastAPI's
# get_swagger_ui_html writes it inline): /docs runs under the same Content-Security-Policy as
# every other page of the service (script-src 'self').
DOCS_PAGE = """<!doctype html>
<html lang="en">
<head>
<meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<title>{title}</title>
<link rel="stylesheet" href="/static/swagger/swagger-ui.css">
<link rel="icon" href="/static/swagger/favicon.png">
</head>
<body>
<div id="swagger-ui"></div>
<script src="/static/swagger/swagger-ui-bundle.js"></script>
<script src="/static/swagger-init.js"></script>
</body>
</html>
"""


@router.get("/docs", include_in_schema=False)
def docs(request: Request) -> HTMLResponse:
    return HTMLResponse(DOCS_PAGE.format(title=html.escape(f"{request.app.title} API")))


@router.get("/static/swagger-init.js", include_in_schema=False)
def swagger_init(request: Request) -> Response:
    """Starts Swagger UI on the service's OpenAPI document (FastAPI's default options)."""
    options = json.dumps({"url": request.app.openapi_url, **swagger_ui_default_parameters}, indent=2)
    script = (
        '"use strict";\n'
        f"const options = {options};\n"
        "options.presets = [SwaggerUIBundle.presets.apis, SwaggerUIBundle.SwaggerUIStandalonePreset];\n"
        "window.ui = SwaggerUIBundle(options);\n"
    )
    return Response(script, media_type="text/javascript")


@router.get("/api/v1/health", tags=["service"], response_model=schemas.Health)
async def health(db: Db, request: Request) -> schemas.Health:
    """Up, on which database; ``warming`` until the workers that answer reads and simulations have
    loaded (``warming`` lists the pools still loading); ``notices`` says what it waits for (a full
    disk: the writes that wait)."""
    compute = request.app.state.compute
    return schemas.Health(
        status="ok" if compute.ready() else "warming",
        warming=compute.warming(),
        database=await db(ping),
        code_version=current_code_version(),
        notices=list(request.app.state.waiting.notices()),
    )


@router.get("/api/v1/auth", tags=["service"], response_model=schemas.TokenAccepted)
async def check_token(request: Request, response: Response) -> schemas.TokenAccepted:
    """Whose the bearer token is: 200 with the person's name and access (``write``: reads and
    changes; ``read``: reads only), 401 if nobody has it. The panel shows it beside the token field.

    It also leaves the token in an HttpOnly, SameSite=Strict cookie on the API's path, which the
    service takes for reads only: a browser's event streams and websockets cannot send a header, and
    a service listening beyond this machine asks a token of every read (backend/api/identity.py)."""
    person = person_of(request)  # as backend/api/security.py's TokenFirst found it, once a request
    if person is None or not signed_in_by_header(request):
        refused = JSONResponse({"detail": TOKEN_UNKNOWN}, status_code=401, headers={"WWW-Authenticate": "Bearer"})
        refused.delete_cookie(READ_COOKIE, path="/api/")
        return refused
    secure = request.url.scheme == "https"
    token = bearer_token(request.headers.get("authorization"))
    response.set_cookie(READ_COOKIE, token, path="/api/", httponly=True, samesite="strict", secure=secure)
    return schemas.TokenAccepted(accepted=True, name=person.name, access=person.access.value)


TOKEN_UNKNOWN = "the bearer token is missing or nobody's: parkour token add NAME makes one (api_token is the lab's)"
