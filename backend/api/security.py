"""Who may change what: the API token, and the limits every request is held to.

Mutating calls carry ``Authorization: Bearer <token>``; the token is created once in the data
directory (``api_token``, mode 600). Reads are open, and so is the robot's e-stop (stopping is
always allowed: docs/service.md). Request bodies larger than the service's limit get a 413.
"""

from __future__ import annotations

import secrets
from pathlib import Path
from typing import Annotated

from fastapi import Depends, FastAPI, HTTPException, Request, status
from fastapi.responses import JSONResponse
from fastapi.security import HTTPAuthorizationCredentials, HTTPBearer

TOKEN_FILE = "api_token"
bearer = HTTPBearer(auto_error=False)


def api_token(data_dir: Path) -> tuple[str, bool]:
    """The bearer token for mutating calls: ``(token, created_now)``; created once, kept in the data dir."""
    path = Path(data_dir) / TOKEN_FILE
    if path.exists():
        return path.read_text().strip(), False
    path.parent.mkdir(parents=True, exist_ok=True)
    token = secrets.token_urlsafe(32)
    path.touch(mode=0o600)
    path.write_text(token + "\n")
    return token, True


def require_token(
    request: Request, credentials: Annotated[HTTPAuthorizationCredentials | None, Depends(bearer)]
) -> None:
    """Mutating calls carry ``Authorization: Bearer <token>``; the token is in the data directory."""
    if credentials is None or not secrets.compare_digest(credentials.credentials, request.app.state.token):
        raise HTTPException(
            status.HTTP_401_UNAUTHORIZED,
            "a valid bearer token is required for changes (see api_token in the data directory)",
            headers={"WWW-Authenticate": "Bearer"},
        )


def limit_request_size(app: FastAPI, max_bytes: int) -> None:
    """Refuse a body whose declared length is over ``max_bytes`` (413)."""

    @app.middleware("http")
    async def limit(request: Request, call_next):
        length = request.headers.get("content-length")
        if length is not None and (not length.isdigit() or int(length) > max_bytes):
            return JSONResponse(
                {"detail": f"request body must be at most {max_bytes} bytes"},
                status_code=status.HTTP_413_CONTENT_TOO_LARGE,
            )
        return await call_next(request)
