"""What the robot link reports: its states and their changes, its one error, and e-stop results.

:mod:`backend.robot.link` uses these and exports them; callers import them from there.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass

from backend.robot.messages import RobotState


class LinkState(enum.StrEnum):
    DISCONNECTED = "disconnected"
    DISARMED = "disarmed"
    ARMED = "armed"
    RUNNING = "running"
    ESTOPPED = "estopped"


FROM_ROBOT = {
    RobotState.DISARMED: LinkState.DISARMED,
    RobotState.ARMED: LinkState.ARMED,
    RobotState.RUNNING: LinkState.RUNNING,
    RobotState.ESTOPPED: LinkState.ESTOPPED,
}

SAFE = (RobotState.DISARMED, RobotState.ESTOPPED)  # what every ending must leave the robot in


def telemetry_moves(current: LinkState, reported: LinkState, *, latched: bool, resetting: bool) -> bool:
    """Whether a TELEMETRY reporting ``reported`` moves a link that is ``current``. E-stopped under
    a held latch, only the RESET under way moves it, to disarmed: a TELEMETRY the robot wrote before
    it latched can be read after its ESTOP's acknowledgement (CI saw ESTOPPED -> ARMED -> ESTOPPED
    under load), and it un-stops nothing."""
    if current == LinkState.ESTOPPED and latched:
        return resetting and reported == LinkState.DISARMED
    return True


class LinkError(RuntimeError):
    """The robot did not answer, refused a command, or the link is down."""


@dataclass(frozen=True)
class EstopResult:
    """What an e-stop achieved: acknowledged by the robot after ``latency`` [s], or not, and why."""

    acknowledged: bool
    latency: float  # [s] from the call to the acknowledgement, or to giving up
    reason: str | None = None  # why it was not acknowledged


@dataclass(frozen=True)
class Transition:
    time: float  # time.time()
    before: LinkState
    after: LinkState
    reason: str

    def to_dict(self) -> dict:
        return {"time": self.time, "from": self.before.value, "to": self.after.value, "reason": self.reason}
