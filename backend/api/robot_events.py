"""The robot's event stream (``GET /api/v1/robot/events``): server-sent events every open panel
follows, whatever tab it shows, so a latched e-stop reaches each within a second (docs/service.md).

Each stream compares the robot's summary — the e-stop latch, the link state, the live run, as
``GET /api/v1/robot`` gives them, from the robot service's lock-free snapshots — with what it last
sent, :data:`EVENT_CHECK_S` apart on the event loop, and sends it when it changed. The number open
at once is bounded per service (:class:`EventStreams`), and a stream ends with its client or when
the service is told to stop (:func:`server_stopping`).
"""

from __future__ import annotations

import asyncio
import json
import signal
import time
from collections.abc import AsyncIterator

from fastapi import HTTPException, Request, status
from fastapi.responses import StreamingResponse
from starlette.types import Receive, Scope, Send

from backend.services.robot import RobotService

MAX_EVENT_STREAMS = 64  # open at once per service; past it a 503 (a script cannot hold them all)
EVENT_CHECK_S = 0.2  # [s] how often each stream compares the robot's summary with what it sent
KEEP_ALIVE_S = 10.0  # [s] of silence before a comment line, so that proxies keep the stream open
RECONNECT_MS = 1000  # [ms] a browser's EventSource waits this long before reconnecting
TOO_MANY_STREAMS = "too many robot event streams are open (at most {}): close a panel, or poll GET /api/v1/robot"


class EventStreams:
    """How many event streams one service has open; counted on its event loop, so without a lock."""

    def __init__(self) -> None:
        self.open = 0


def event_streams(request: Request) -> EventStreams:
    """The service's count of open event streams (made at its first stream, kept on ``app.state``)."""
    streams = getattr(request.app.state, "robot_event_streams", None)
    if streams is None:
        streams = request.app.state.robot_event_streams = EventStreams()
    return streams


class EventStreamResponse(StreamingResponse):
    """A stream that gives its place back however it ends: the client gone, the service stopping,
    or an error."""

    def __init__(self, content: AsyncIterator[str], streams: EventStreams) -> None:
        headers = {"Cache-Control": "no-cache", "X-Accel-Buffering": "no"}  # no proxy holds events back
        super().__init__(content, media_type="text/event-stream", headers=headers)
        self.streams = streams

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        try:
            await super().__call__(scope, receive, send)
        finally:
            self.streams.open -= 1


def server_stopping() -> bool:
    """Whether the uvicorn serving this process has been told to stop (SIGTERM, Ctrl-C).

    uvicorn waits for every response to finish before it shuts down, and tells a streaming one
    nothing: it only sets ``should_exit`` on itself, from its signal handler — which, while it
    serves from the main thread (``parkour serve``), is its own bound ``handle_exit``. A uvicorn run
    in another thread (some tests) installs no handler: there a stream ends only with its client."""
    handler = signal.getsignal(signal.SIGTERM)
    return bool(getattr(getattr(handler, "__self__", None), "should_exit", False))


def robot_summary(robot: RobotService) -> str:
    """What the event stream sends, as one line of JSON: the e-stop latch, the link state, the run."""
    now = robot.status()
    return json.dumps({"estop": now["estop"], "state": now["state"], "run": now["run"]}, separators=(",", ":"))


async def robot_events_of(robot: RobotService) -> AsyncIterator[str]:
    """Server-sent events: the reconnect delay, then an ``event: robot`` at once and whenever its
    summary changes, a comment after :data:`KEEP_ALIVE_S` of silence; until the service stops."""
    yield f"retry: {RECONNECT_MS}\n\n"
    sent, last = None, 0.0
    while not server_stopping():
        summary = robot_summary(robot)  # lock-free, from immutable snapshots (services/robot.py)
        if summary != sent:
            yield f"event: robot\ndata: {summary}\n\n"
            sent, last = summary, time.monotonic()
        elif time.monotonic() - last >= KEEP_ALIVE_S:
            yield ": keep-alive\n\n"
            last = time.monotonic()
        await asyncio.sleep(EVENT_CHECK_S)


def open_event_stream(request: Request, robot: RobotService) -> EventStreamResponse:
    """A new stream of ``robot``'s events, or a 503 past :data:`MAX_EVENT_STREAMS` open at once."""
    streams = event_streams(request)
    if streams.open >= MAX_EVENT_STREAMS:
        raise HTTPException(status.HTTP_503_SERVICE_UNAVAILABLE, TOO_MANY_STREAMS.format(MAX_EVENT_STREAMS))
    streams.open += 1  # given back by the response, however it ends
    return EventStreamResponse(robot_events_of(robot), streams)
