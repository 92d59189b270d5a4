"""The service itself: health, the panel's entry, local copies of Plotly and the API docs."""

from __future__ import annotations

from pathlib import Path

import fastapi_offline
import plotly
from fastapi import APIRouter, Request
from fastapi.openapi.docs import get_swagger_ui_html
from fastapi.responses import FileResponse, HTMLResponse, RedirectResponse
from sqlalchemy import select

from backend.api.deps import Db
from backend.services import simulation

SWAGGER_ASSETS = Path(fastapi_offline.__file__).parent / "static"  # Swagger UI 5: reads OpenAPI 3.1
PLOTLY_JS = Path(plotly.__file__).parent / "package_data" / "plotly.min.js"  # served locally: no CDN

router = APIRouter()


@router.get("/", include_in_schema=False)
def index() -> RedirectResponse:
    return RedirectResponse("/panel/")


@router.get("/static/plotly.min.js", include_in_schema=False)
def plotly_js() -> FileResponse:
    return FileResponse(PLOTLY_JS, media_type="text/javascript")


@router.get("/docs", include_in_schema=False)
def docs(request: Request) -> HTMLResponse:
    return get_swagger_ui_html(
        openapi_url=request.app.openapi_url,
        title="ParkourLab API",
        swagger_js_url="/static/swagger/swagger-ui-bundle.js",
        swagger_css_url="/static/swagger/swagger-ui.css",
        swagger_favicon_url="/static/swagger/favicon.png",
    )


@router.get("/api/v1/health", tags=["service"])
def health(db: Db) -> dict:
    db.execute(select(1))
    return {"status": "ok", "database": db.get_bind().dialect.name, "code_version": simulation.current_code_version()}
