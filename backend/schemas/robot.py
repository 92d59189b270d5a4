"""The robot: opening the link, and a live run (open or closed loop), each bounded."""

from __future__ import annotations

from typing import Annotated

from pydantic import Field, field_validator

from backend.robot.ports import check_port
from backend.robot.xbee import ROBOT_ADDRESS
from backend.schemas.common import LegIn, Psi0Deg, RecordRef, Strict, Tags, Zeta0


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
    tracker_port: Annotated[int, Field(ge=0, le=65535)] = 9751
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


class ClosedLoopIn(Strict):
    target_m: Annotated[float, Field(gt=0.0, le=100.0, description="height to hold [m]")]
    kp: Annotated[float, Field(ge=0.0, le=10.0)] = 0.04
    ki: Annotated[float, Field(ge=0.0, le=10.0)] = 0.0
    kd: Annotated[float, Field(ge=0.0, le=10.0)] = 0.02
    zeta0_min: Zeta0 = 0.80
    zeta0_max: Zeta0 = 0.98


class RobotRunCreate(Strict):
    """A live run: the left and right legs' controls, bounded in jumps and time; optionally closed loop."""

    experiment_id: RecordRef | None = None
    controls: Annotated[list[LegIn], Field(min_length=2, max_length=2, description="[left, right]")]
    jumps: Annotated[int, Field(ge=1, le=10_000)] = 20
    max_seconds: Annotated[float, Field(gt=0.0, le=3600.0)] = 60.0
    closed_loop: ClosedLoopIn | None = None
    tags: Tags = []
