"""A request sent to the ASGI application itself, its body pulled chunk by chunk and counted — so a
test sees how much of a body the service read before it answered (TestClient reads a streamed body
whole before the application sees any of it)."""

from __future__ import annotations

import asyncio
import json
from dataclasses import dataclass, field

CHUNK = 64 * 1024


@dataclass
class Answer:
    status: int = 0
    headers: dict[str, str] = field(default_factory=dict)
    body: bytes = b""
    pulled: int = 0  # body bytes the application asked for

    def json(self):
        return json.loads(self.body)


def send_chunked(app, method: str, path: str, *, total: int, headers: dict[str, str] | None = None) -> Answer:
    """``method path`` with a chunked body of ``total`` bytes (``Transfer-Encoding: chunked``, no
    Content-Length), handed to ``app`` in 64 KiB chunks only as it asks for them."""
    answer = Answer()
    sent = {"Host": "localhost:8000", "Content-Type": "application/json", "Transfer-Encoding": "chunked"}
    sent |= headers or {}

    async def receive():
        left = total - answer.pulled
        if left <= 0:
            await asyncio.sleep(3600)  # the client has nothing more to say (a disconnect would end it)
        chunk = b"x" * min(CHUNK, left)
        answer.pulled += len(chunk)
        return {"type": "http.request", "body": chunk, "more_body": answer.pulled < total}

    async def send(message):
        if message["type"] == "http.response.start":
            answer.status = message["status"]
            answer.headers = {key.decode().lower(): value.decode() for key, value in message.get("headers", [])}
        elif message["type"] == "http.response.body":
            answer.body += message.get("body", b"")

    scope = {
        "type": "http",
        "asgi": {"version": "3.0"},
        "http_version": "1.1",
        "method": method,
        "scheme": "http",
        "path": path,
        "raw_path": path.encode(),
        "query_string": b"",
        "root_path": "",
        "headers": [(key.lower().encode(), value.encode()) for key, value in sent.items()],
        "client": ("127.0.0.1", 50000),
        "server": ("127.0.0.1", 8000),
        "state": {},
    }
    asyncio.run(asyncio.wait_for(app(scope, receive, send), timeout=30))
    return answer
