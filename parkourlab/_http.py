"""The client's one road to the service: a sync ``httpx.Client`` with the token, every error
answer turned into the exception for its status (parkourlab/errors.py), downloads written to a
file whole or not at all."""

from __future__ import annotations

import ipaddress
import os
import re
import socket
from collections.abc import Iterator, Mapping
from datetime import date, datetime
from enum import Enum
from pathlib import Path
from typing import Any
from urllib.parse import urlsplit

import httpx

from parkourlab.errors import FieldError, ServiceUnreachable, Unauthorized, error_for

DEFAULT_URL = "http://127.0.0.1:8000"  # where `parkour serve` (./run.sh) listens
URL_ENV = "PARKOUR_URL"
TOKEN_ENV = "PARKOUR_API_TOKEN"
DATA_DIR_ENV = "PARKOUR_DATA_DIR"  # the service's own: its data directory holds api_token
TOKEN_FILE = "api_token"
NO_TOKEN = f"this client has no token: pass Client(token=...) or set ${TOKEN_ENV} (<data dir>/{TOKEN_FILE})"
CHUNK_BYTES = 1 << 16  # of a download, written as it comes
# [s] The service bounds a call's computation at 60 s (backend/workers/pools.py, QUICK_TIMEOUT) and
# then answers 503 saying so; a client that gave up at the same moment showed a bare ReadTimeout
# instead of that message (issue 40). So the client waits longer than the service by default.
DEFAULT_TIMEOUT = 90.0
CONNECT_TIMEOUT = 10.0  # [s] to open a connection: a service that is not there fails fast


def service_url(url: str | None) -> str:
    """The service's base URL without a trailing slash: ``url``, else ``$PARKOUR_URL``, else
    ``http://127.0.0.1:8000``."""
    return (url or os.environ.get(URL_ENV) or DEFAULT_URL).rstrip("/")


def find_token(url: str) -> str | None:
    """The bearer token: ``$PARKOUR_API_TOKEN``; else, for a service on this machine (a loopback
    URL) only, the ``api_token`` file of its data directory, ``$PARKOUR_DATA_DIR`` or ``./data``
    as ``parkour serve`` chooses it. A remote service is never sent the local service's token."""
    if token := os.environ.get(TOKEN_ENV, "").strip():
        return token
    if not is_loopback(url):
        return None
    path = Path(os.environ.get(DATA_DIR_ENV) or "data") / TOKEN_FILE
    try:
        return path.read_text().strip() or None
    except (OSError, UnicodeDecodeError):
        return None


def is_loopback(url: str) -> bool:
    """Whether ``url`` names this machine (``localhost``, 127.0.0.0/8, ``[::1]``)."""
    host = urlsplit(url).hostname or ""
    if host == "localhost":
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False


def query(params: Mapping[str, Any]) -> dict[str, Any]:
    """Query parameters as the API reads them: None left out, enums by value, datetimes in ISO 8601,
    booleans as ``true``/``false``."""
    out: dict[str, Any] = {}
    for name, value in params.items():
        if value is None:
            continue
        if isinstance(value, Enum):
            value = value.value
        if isinstance(value, datetime | date):
            value = value.isoformat()
        elif isinstance(value, bool):
            value = "true" if value else "false"
        out[name] = value
    return out


class Http:
    """A sync HTTP session on one service: ``call`` for JSON, ``download`` for files."""

    def __init__(
        self, url: str, token: str | None, timeout: float, transport: httpx.BaseTransport | None, name: str
    ) -> None:
        self.url, self.token = url, token
        headers = {"X-Parkour-Client": name} | ({"Authorization": f"Bearer {token}"} if token else {})
        limit = httpx.Timeout(timeout, connect=min(timeout, CONNECT_TIMEOUT))
        self.client = httpx.Client(base_url=url, headers=headers, timeout=limit, transport=transport)

    def close(self) -> None:
        self.client.close()

    def call(
        self,
        method: str,
        path: str,
        *,
        params: Mapping[str, Any] | None = None,
        body: Any = None,
        timeout: float | None = None,
    ) -> Any:
        """``METHOD path`` with query ``params`` and JSON ``body``; the answer's JSON (None when empty).
        ``timeout`` [s]: this call's, when shorter than the client's (a poll's)."""
        limit = self.client.timeout if timeout is None else httpx.Timeout(timeout, connect=CONNECT_TIMEOUT)
        try:
            response = self.client.request(method, path, params=query(params or {}), json=body, timeout=limit)
        except httpx.TransportError as error:
            raise self._unreachable(error) from error
        if response.is_error:
            raise self._error(response, f"{method} {path}")
        return response.json() if response.content else None

    def pages(self, path: str, params: Mapping[str, Any], page_size: int) -> Iterator[Any]:
        """Every item of a keyset-paged list, ``page_size`` a request (``next_cursor`` passed back
        as ``cursor``)."""
        cursor = None
        while True:
            page = self.call("GET", path, params={**params, "limit": page_size, "cursor": cursor})
            yield from page["items"]
            if (cursor := page.get("next_cursor")) is None:
                return

    def succeeds(self, method: str, path: str) -> bool:
        """Whether ``METHOD path`` answers a success status (an error status is False, not raised)."""
        try:
            return self.client.request(method, path).is_success
        except httpx.TransportError as error:
            raise self._unreachable(error) from error

    def download(self, path: str, target: Path, params: Mapping[str, Any] | None = None) -> Path:
        """``GET path`` streamed into ``target``, through ``target.part`` renamed at the end: an
        error or a broken connection leaves no half file under the name."""
        target = Path(target)
        partial = target.with_name(target.name + ".part")
        try:
            with self.client.stream("GET", path, params=query(params or {})) as response:
                if response.is_error:
                    response.read()
                    raise self._error(response, f"GET {path}")
                with partial.open("wb") as out:
                    for chunk in response.iter_bytes(CHUNK_BYTES):
                        out.write(chunk)
        except httpx.TransportError as error:
            partial.unlink(missing_ok=True)
            raise self._unreachable(error) from error
        except BaseException:
            partial.unlink(missing_ok=True)
            raise
        partial.replace(target)
        return target

    def _unreachable(self, error: httpx.TransportError) -> ServiceUnreachable:
        if isinstance(error, httpx.ConnectTimeout):
            reason = f"no connection within {CONNECT_TIMEOUT:g} s"
        elif isinstance(error, httpx.TimeoutException):
            reason = f"no answer within the client's timeout ({type(error).__name__})"
        elif isinstance(error, httpx.ConnectError) and "refused" in str(error).lower():
            reason = "connection refused"
        else:
            reason = str(error) or type(error).__name__
        return ServiceUnreachable(self.url, reason)

    def _error(self, response: httpx.Response, request: str):
        try:
            body = response.json()
        except ValueError:
            body = response.text
        error = error_for(response.status_code, body, request)
        if isinstance(error, Unauthorized) and not self.token:
            hint = FieldError(field="", message=NO_TOKEN)
            error = Unauthorized(error.status, error.detail, [*error.errors, hint], request)
        return error


def client_name(name: str | None) -> str:
    """Who this client is to the service (``X-Parkour-Client``: the job queue's share is per client):
    ``name``, else ``python@<this host>``; characters the header refuses become ``-``."""
    chosen = name or f"python@{socket.gethostname()}"
    return re.sub(r"[^\w.:@/-]", "-", chosen)[:64] or "python"
