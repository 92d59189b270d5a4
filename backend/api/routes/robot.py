"""The robot: one link per service; every call that moves or commands it needs the token, except
the e-stop — stopping is always allowed (docs/service.md)."""

from __future__ import annotations

import asyncio
from typing import Annotated

from fastapi import APIRouter, Query, Request, WebSocket, WebSocketDisconnect
from fastapi.responses import StreamingResponse

from backend import schemas
from backend.api.deps import AUTHORIZED, Robot, Who
from backend.api.robot_events import open_event_stream

router = APIRouter(prefix="/api/v1/robot", tags=["robot"])


@router.get("", response_model=schemas.RobotStatus)
def robot_status(robot: Robot) -> schemas.RobotStatus:
    return schemas.RobotStatus.model_validate(robot.status())


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


@router.get("/events", response_class=StreamingResponse)
async def robot_events(request: Request, robot: Robot) -> StreamingResponse:
    """Server-sent events (``text/event-stream``) for every open panel, whatever tab it shows:
    ``event: robot`` with ``{"estop", "state", "run"}`` as GET /api/v1/robot gives them, at once and
    within a fraction of a second of any change; a comment line every 10 s of quiet. It ends when
    the client goes away or the service stops. Past the bound of open streams, a 503."""
    return open_event_stream(request, robot)


@router.post("/connect", dependencies=AUTHORIZED, response_model=schemas.RobotStatus)
def robot_connect(body: schemas.RobotConnect, robot: Robot) -> schemas.RobotStatus:
    return schemas.RobotStatus.model_validate(robot.connect(body))


@router.post("/disconnect", dependencies=AUTHORIZED, response_model=schemas.RobotStatus)
def robot_disconnect(robot: Robot) -> schemas.RobotStatus:
    return schemas.RobotStatus.model_validate(robot.disconnect())


@router.post("/arm", dependencies=AUTHORIZED, response_model=schemas.RobotStatus)
def robot_arm(robot: Robot) -> schemas.RobotStatus:
    return schemas.RobotStatus.model_validate(robot.arm())


@router.post("/disarm", dependencies=AUTHORIZED, response_model=schemas.RobotStatus)
def robot_disarm(robot: Robot) -> schemas.RobotStatus:
    return schemas.RobotStatus.model_validate(robot.disarm())


@router.post("/reset", dependencies=AUTHORIZED, response_model=schemas.RobotStatus)
def robot_reset(robot: Robot, person: Who) -> schemas.RobotStatus:
    return schemas.RobotStatus.model_validate(robot.reset(by=person))


# No token, async, and on the robot service's own e-stop thread: a request pool filled by compute
# cannot hold it back.
@router.post("/estop", response_model=schemas.RobotEstopOut, response_model_exclude_unset=True)
async def robot_estop(robot: Robot, person: Who) -> schemas.RobotEstopOut:
    """Emergency stop, at any moment and without the token; answers within 200 ms. A live run
    ends (and is stored). ``acknowledged`` says whether the robot confirmed it (``latency_ms``);
    if not (``reason``: link blocked or lost), the robot's 1 s watchdog disarms it."""
    return schemas.RobotEstopOut.model_validate(await robot.estop_now(by=person))


@router.post("/runs", status_code=202, dependencies=AUTHORIZED, response_model=schemas.RobotStatus)
def robot_run(body: schemas.RobotRunCreate, robot: Robot, person: Who) -> schemas.RobotStatus:
    """Start a live run: stored at once (status running, ``run.id``), journaled while it runs,
    complete when it ends (see GET /api/v1/robot). Every panel is told who started it: the token's
    person (with ``operator`` beside it when that names someone else at the table), who is also the
    run's ``created_by``. While it runs, link changes are refused (409 naming it)."""
    started_by = person if body.operator in (None, person) else f"{person} (operator: {body.operator})"
    robot.start_run(body, started_by=started_by, person=person)
    return schemas.RobotStatus.model_validate(robot.status())


@router.post("/runs/stop", dependencies=AUTHORIZED, response_model=schemas.RobotStatus)
def robot_run_stop(robot: Robot) -> schemas.RobotStatus:
    return schemas.RobotStatus.model_validate(robot.stop_run())
