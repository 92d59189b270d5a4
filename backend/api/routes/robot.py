"""The robot: one link per service; every call that moves or commands it needs the token, except
the e-stop — stopping is always allowed (docs/service.md)."""

from __future__ import annotations

import asyncio
import json
import signal
import time
from collections.abc import AsyncIterator
from typing import Annotated

from fastapi import APIRouter, HTTPException, Query, Request, WebSocket, WebSocketDisconnect, status
from fastapi.responses import StreamingResponse
from starlette.types import Receive, Scope, Send

from backend import schemas
from backend.api.deps import AUTHORIZED, Robot
from backend.services.robot import RobotService

router = APIRouter(prefix="/api/v1/robot", tags=["robot"])


@router.get("")
def robot_status(robot: Robot) -> dict:
    return robot.status()


@router.websocket("/live")
async def robot_live(
    websocket: WebSocket,
    rate: Annotated[float, Query(gt=0, le=50, allow_inf_nan=False, description="messages per second")] = 20,
):
    """Live state for the panel: link state, telemetry, the latest tracked pose, the run's
    newest touchdowns — ``rate`` messages per second until the client goes away."""
    robot = websocket.app.state.robot
    await websocket.accept()
    try:
        while True:
            # Built from immutable snapshots under no lock that waits: on the event loop itself,
            # so a request pool full of compute cannot stall the live view.
            await websocket.send_json(robot.live())
            await asyncio.sleep(1.0 / rate)
    except (WebSocketDisconnect, RuntimeError):
        return


# The event stream --------------------------------------------------------------------------------
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


@router.get("/events", response_class=StreamingResponse)
async def robot_events(request: Request, robot: Robot) -> StreamingResponse:
    """Server-sent events (``text/event-stream``) for every open panel, whatever tab it shows:
    ``event: robot`` with ``{"estop": {"latched", "reason"}, "state", "run"}`` as GET /api/v1/robot
    gives them, at once and within a fraction of a second of any change; a comment line every 10 s
    of quiet. It ends when the client goes away or the service stops. At most
    :data:`MAX_EVENT_STREAMS` are open at once: past that, a 503."""
    streams = event_streams(request)
    if streams.open >= MAX_EVENT_STREAMS:
        raise HTTPException(status.HTTP_503_SERVICE_UNAVAILABLE, TOO_MANY_STREAMS.format(MAX_EVENT_STREAMS))
    streams.open += 1  # given back by the response, however it ends
    return EventStreamResponse(robot_events_of(robot), streams)


@router.post("/connect", dependencies=AUTHORIZED)
def robot_connect(body: schemas.RobotConnect, robot: Robot) -> dict:
    return robot.connect(body)


@router.post("/disconnect", dependencies=AUTHORIZED)
def robot_disconnect(robot: Robot) -> dict:
    return robot.disconnect()


@router.post("/arm", dependencies=AUTHORIZED)
def robot_arm(robot: Robot) -> dict:
    return robot.arm()


@router.post("/disarm", dependencies=AUTHORIZED)
def robot_disarm(robot: Robot) -> dict:
    return robot.disarm()


@router.post("/reset", dependencies=AUTHORIZED)
def robot_reset(robot: Robot) -> dict:
    return robot.reset()


# No token, async, and on the robot service's own e-stop thread: a request pool filled by compute
# cannot hold it back.
@router.post("/estop")
async def robot_estop(robot: Robot) -> dict:
    """Emergency stop, at any moment and without the token; answers within 200 ms. A live run
    ends (and is stored). ``acknowledged`` says whether the robot confirmed it (``latency_ms``);
    if not (``reason``: link blocked or lost), the robot's 1 s watchdog disarms it."""
    return await robot.estop_now()


@router.post("/runs", status_code=202, dependencies=AUTHORIZED)
def robot_run(body: schemas.RobotRunCreate, robot: Robot, request: Request) -> dict:
    """Start a live run: stored at once (status running, ``run.id``), journaled while it runs,
    complete when it ends (see GET /api/v1/robot). Every panel is told who started it: ``operator``,
    or the client's address. While it runs, link changes are refused (409 naming it)."""
    client = request.client.host if request.client is not None else "unknown"
    robot.start_run(body, started_by=body.operator or f"a client at {client}")
    return robot.status()


@router.post("/runs/stop", dependencies=AUTHORIZED)
def robot_run_stop(robot: Robot) -> dict:
    return robot.stop_run()
