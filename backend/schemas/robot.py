"""The robot: opening the link, and a live run (open or closed loop), each bounded."""

from __future__ import annotations

import ipaddress
from typing import Annotated, Any, Literal

from pydantic import BaseModel, Field, ValidationInfo, field_validator, model_validator

from backend.robot.natnet import COMMAND_PORT, MULTICAST_GROUP, parse_version
from backend.robot.ports import check_port
from backend.robot.tracker_watch import TRACKER_TIMEOUT_MS, TRACKER_TIMEOUT_RANGE_MS
from backend.robot.xbee import ROBOT_ADDRESS
from backend.schemas.common import LegIn, Psi0Deg, RecordRef, Strict, Tags, Zeta0
from sim_core.climb.records import CHUTE_TOP, FLOOR
from sim_core.control.design import DEADBEAT_CLIMB_PER_JUMP
from sim_core.control.registry import NAMES


class RobotConnect(Strict):
    """Open the link: a pyserial URL (``/dev/ttyUSB0``, ``socket://host:port``) and the tracker's UDP port."""

    # Serial devices and ptys (symlinks followed), the virtual robot's socket, RFC 2217, a loopback:
    # never a regular file or another device (backend.robot.ports).
    url: Annotated[
        str,
        Field(max_length=200, description="a serial device or pty, socket://host:port, rfc2217://host:port, loop://"),
    ]
    robot_address: Annotated[
        str,
        Field(
            pattern=r"^(0x)?[0-9A-Fa-f]{16}$",
            description="the robot radio's 64-bit address (its XBee's SH:SL, hex); frames from any other are dropped",
        ),
    ] = f"0x{ROBOT_ADDRESS:016X}"
    baud: Annotated[int, Field(ge=1200, le=1_000_000)] = 57_600
    tracker_host: Annotated[str, Field(max_length=100, pattern=r"^[\w.:-]+$")] = "127.0.0.1"
    tracker_port: Annotated[
        int, Field(ge=0, le=65535, description="the tracker's UDP port here (NatNet multicast: its data port, 1511)")
    ] = 9751
    tracker_protocol: Annotated[
        Literal["pkt1", "natnet"], Field(description="pkt1: ParkourLab datagrams; natnet: the camera software's stream")
    ] = "pkt1"
    natnet_rigid_body_id: Annotated[int, Field(ge=0, le=2**31 - 1, description="the body's NatNet streaming id")] = 1
    natnet_version: Annotated[
        str, Field(max_length=8, description="the stream's NatNet version (2.0 to 4.x), or auto: the server's answer")
    ] = "auto"
    natnet_multicast_group: Annotated[
        str | None,
        Field(max_length=15, description="the stream's multicast group; null: unicast (connect to the server)"),
    ] = MULTICAST_GROUP
    natnet_server_host: Annotated[
        str, Field(max_length=100, pattern=r"^[\w.:-]+$", description="the NatNet server")
    ] = "127.0.0.1"
    natnet_command_port: Annotated[int, Field(ge=1, le=65535, description="the NatNet server's command port")] = (
        COMMAND_PORT
    )
    calibration_origin: Annotated[list[Annotated[float, Field(ge=-1e4, le=1e4)]], Field(min_length=2, max_length=2)] = [
        0.0,
        0.0,
    ]
    calibration_angle: Annotated[float, Field(ge=-3.2, le=3.2, description="camera rotation [rad]")] = 0.0
    calibration_scale: Annotated[float, Field(gt=0.0, le=1e4, description="metres per camera unit")] = 1.0
    psi0_limits_deg: Annotated[list[Psi0Deg], Field(min_length=2, max_length=2)] = [10.0, 60.0]
    zeta0_limits: Annotated[list[Zeta0], Field(min_length=2, max_length=2)] = [0.75, 0.98]

    @field_validator("url")
    @classmethod
    def _openable(cls, url: str) -> str:
        return check_port(url)

    @field_validator("natnet_version")
    @classmethod
    def _known_version(cls, version: str) -> str:
        if version != "auto":
            parse_version(version)  # a ParameterError (a ValueError) names the field and the range
        return version

    @field_validator("natnet_multicast_group")
    @classmethod
    def _multicast(cls, group: str | None) -> str | None:
        if group is not None:
            try:
                address = ipaddress.IPv4Address(group)
            except ValueError:
                raise ValueError(
                    f"must be an IPv4 multicast address such as {MULTICAST_GROUP}, got {group!r}"
                ) from None
            if not address.is_multicast:
                raise ValueError(f"must be a multicast address (224.0.0.0 to 239.255.255.255), got {group}")
        return group


class ClosedLoopIn(Strict):
    """A closed loop: ``controller`` holds ``target_m`` from each touchdown to the next leg
    (docs/analyses.md, "Controllers"); the PIDs take the gains, every law the zeta0 range, the
    deadbeat and the placement law their climb per jump. The model-based laws are designed on ``preset`` (a stored
    calibration gives its own controller, its leg offsets taken off each command), else on the
    service's robot."""

    target_m: Annotated[
        float, Field(gt=FLOOR, le=CHUTE_TOP, description="height to hold [m], above the floor, within the chute")
    ]
    controller: Annotated[str, Field(description=f"the law, one of: {', '.join(NAMES)}")] = "pid"
    kp: Annotated[float, Field(ge=0.0, le=10.0)] = 0.04
    ki: Annotated[float, Field(ge=0.0, le=10.0)] = 0.0
    kd: Annotated[float, Field(ge=0.0, le=10.0)] = 0.02
    zeta0_min: Zeta0 = 0.80
    zeta0_max: Zeta0 = 0.98
    climb_per_jump: Annotated[
        float, Field(gt=0.0, le=1.0, description="deadbeat, placement: the most it climbs to the target a jump [l0]")
    ] = DEADBEAT_CLIMB_PER_JUMP
    preset: Annotated[
        str | None,
        Field(
            min_length=1,
            max_length=80,
            description="the model the law is designed on: a built-in preset or a "
            "stored calibration, whose leg offsets are taken off each command (default: the service's robot)",
        ),
    ] = None

    @field_validator("controller")
    @classmethod
    def _known(cls, name: str) -> str:
        if name not in NAMES:
            raise ValueError(f"must be one of {', '.join(NAMES)}, got {name!r}")
        return name

    @field_validator("zeta0_max")
    @classmethod
    def _above_the_min(cls, zeta0_max: float, info: ValidationInfo) -> float:
        zeta0_min = info.data.get("zeta0_min")
        if zeta0_min is not None and not zeta0_min < zeta0_max:
            raise ValueError(f"must exceed zeta0_min = {zeta0_min:g}, got {zeta0_max:g}")
        return zeta0_max


class RobotRunCreate(Strict):
    """A live run: the left and right legs' controls, bounded in jumps and time; optionally closed
    loop, or following a plan (``plan_job_id``: a finished ``plan`` job, in the world the robot
    climbs; its legs start the run)."""

    experiment_id: RecordRef | None = None
    controls: Annotated[list[LegIn] | None, Field(min_length=2, max_length=2, description="[left, right]")] = None
    world_id: RecordRef | None = Field(None, description="the stored world the robot climbs; null: parallel walls")
    plan_job_id: RecordRef | None = Field(
        None, description="a finished plan job whose plan the run follows with the placement law (its world)"
    )
    jumps: Annotated[int, Field(ge=1, le=10_000)] = 20
    max_seconds: Annotated[float, Field(gt=0.0, le=3600.0)] = 60.0
    closed_loop: ClosedLoopIn | None = None
    tracker_timeout_ms: Annotated[
        float,
        Field(
            ge=TRACKER_TIMEOUT_RANGE_MS[0],
            le=TRACKER_TIMEOUT_RANGE_MS[1],
            description="the longest without a pose of the robot [ms]: a closed loop ends then, disarmed "
            "(tracker silent, or the body lost); an open loop goes on and records the gap",
        ),
    ] = TRACKER_TIMEOUT_MS
    tags: Tags = []
    operator: Annotated[
        str | None,
        Field(min_length=1, max_length=80, description="who runs it, as every panel is told (default: the client)"),
    ] = None

    @model_validator(mode="after")
    def _one_way_to_move(self) -> RobotRunCreate:
        if (self.controls is None) == (self.plan_job_id is None):
            raise ValueError("give either controls [left, right] or plan_job_id (its plan's legs), not both")
        if self.plan_job_id is not None and self.closed_loop is not None:
            raise ValueError("a run follows a plan or holds a height (closed_loop), not both")
        return self


class EstopLatchOut(BaseModel):
    """The e-stop latch: held until a RESET is acknowledged."""

    latched: bool
    acknowledged: bool = Field(description="the robot has confirmed the ESTOP on this connection")
    since: float | int | None = Field(description="when it was pressed [Unix time, s], or null")
    reason: str | None
    durable: bool = Field(True, description="the latch as it is now is saved: a restart of the service finds it")
    pressed_by: str | None = Field(
        None, description="who pressed the e-stop that holds it (a person, or someone at an address)"
    )
    reset_by: str | None = Field(None, description="who last reset the latch")
    reset_at: float | int | None = Field(None, description="when it was last reset [Unix time, s]")


class RobotStatus(BaseModel):
    """The robot as it is now (``GET /api/v1/robot``, and the answer of every command): the link,
    its counters and the robot's telemetry, the e-stop latch, the tracker, the live run and the
    link's last transitions. Nested shapes that grow with the link and tracker are open objects."""

    state: str = Field(description="the link's state: disconnected, disarmed, armed, estopped, ...")
    url: str | None
    robot_address: str | None = Field(description="the robot radio's 64-bit address, 0x + 16 hex digits")
    counters: dict[str, Any] | None = Field(description="the link's frame counts and reconnects")
    estop: EstopLatchOut
    last_delivery_failure: Any
    telemetry: dict[str, Any] | None
    tracker: dict[str, Any] | None = Field(description="the tracker's address, counts, protocol and latest pose")
    run: dict[str, Any] | None = Field(description="the live run, or the last one")
    transitions: list[dict[str, Any]] = Field(description="the link's last 20 state changes")


class EstopAnswer(BaseModel):
    acknowledged: bool = Field(description="whether the robot confirmed the e-stop")
    latency_ms: float
    reason: str | None = Field(None, description="why not acknowledged (absent when it was)")


class RobotEstopOut(RobotStatus, EstopAnswer):
    """The e-stop's answer: whether the robot acknowledged it, how fast, and the status after it."""
