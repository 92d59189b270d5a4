"""The service itself: health, the panel's entry, local copies of Plotly and the API docs."""

from __future__ import annotations

import html
import json
from pathlib import Path

import fastapi_offline
import plotly
from fastapi import APIRouter, Request
from fastapi.openapi.docs import swagger_ui_default_parameters
from fastapi.responses import FileResponse, HTMLResponse, RedirectResponse, Response

from backend import schemas
from backend.api.deps import AUTHORIZED, Db
from backend.services import simulation
from backend.store.database import ping

SWAGGER_ASSETS = Path(fastapi_offline.__file__).parent / "static"  # Swagger UI 5: reads OpenAPI 3.1
PLOTLY_JS = Path(plotly.__file__).parent / "package_data" / "plotly.min.js"  # served locally: no CDN

router = APIRouter()


@router.get("/", include_in_schema=False)
def index() -> RedirectResponse:
    return RedirectResponse("/panel/")


@router.get("/static/plotly.min.js", include_in_schema=False)
def plotly_js() -> FileResponse:
    return FileResponse(PLOTLY_JS, media_type="text/javascript")


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
async def health(db: Db) -> schemas.Health:
    return schemas.Health(status="ok", database=await db(ping), code_version=simulation.current_code_version())


@router.get("/api/v1/auth", tags=["service"], dependencies=AUTHORIZED, response_model=schemas.TokenAccepted)
async def check_token() -> schemas.TokenAccepted:
    """Whether the bearer token is the service's: 200 if so, 401 if not. The panel shows it beside
    the token field; reads need no token, changes do."""
    return schemas.TokenAccepted(accepted=True)
