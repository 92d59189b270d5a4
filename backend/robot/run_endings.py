"""Why a live run ends, in the operator's words — and what that says about the robot.

Every end reason is a family and, after a colon, its particulars ("fell: …", "tracker silent: …"):
History filters by the family (a reason as stored, or every reason that starts with it and a
colon). A run that ends so is ``done``: :data:`CLEAN_ENDINGS`; any other ending is ``failed``.

When the robot itself leaves ``running``, its telemetry says why, and the reason names it: a fall
(the firmware's FELL fault), a restart of the robot (its sequence began again, or it reports
having just booted; a brown-out says so), its watchdog (no heartbeat from the PC), or none of
these. Before, all of them read "robot disarmed (fell or timed out)"; runs stored so keep that
reason, and :func:`fell` still reads them.
"""

from __future__ import annotations

from backend.robot.link_types import LinkError, LinkState
from backend.robot.messages import Fault

GOAL_REACHED = "goal reached"  # a run following a plan: a foot at the plan's goal
MISSED_FOOTHOLD = "missed foothold"  # ... a foot landed off the plan's foothold
OFF_PLAN = "off plan"  # ... no leg lands on the plan's next foothold (or the plan ended below its goal)
CLEAN_ENDINGS = ("jumps done", "stopped", "time limit", GOAL_REACHED)  # a run that ended so is "done", else "failed"
LEGACY_SELF_DISARMED = "robot disarmed (fell or timed out)"  # how runs before these names ended so

FELL = "fell"
RESTARTED = "robot restarted"
SELF_DISARMED = "robot disarmed itself"
LINK_LOST = "link lost"
ESTOP = "e-stop"


def fault_names(faults: int) -> list[str]:
    """The TELEMETRY fault bits set in ``faults``, by name (``["fell", "heartbeat_lost"]``)."""
    return [fault.name.lower() for fault in Fault if faults & fault]


def robot_ending(state: LinkState, faults: int, restart: str | None, touchdowns: int) -> str:
    """Why a run ends whose link is no longer ``running``: ``state`` the link's, ``faults`` the
    robot's latest telemetry's, ``restart`` the link's account of a restart of the robot during
    the run (None: none), ``touchdowns`` detected so far."""
    if state == LinkState.DISCONNECTED:
        return LINK_LOST
    if state == LinkState.ESTOPPED:
        return ESTOP
    if restart is not None:  # the link says "robot restarted (brown-out; its sequence went back …)"
        detail = restart.removeprefix(RESTARTED).strip().removeprefix("(").removesuffix(")")
        return f"{RESTARTED}: {detail or 'it reports having just booted'}"
    if faults & Fault.FELL:
        return f"{FELL}: the robot reported a fall (FELL) after touchdown {touchdowns}"
    if faults & Fault.HEARTBEAT_LOST:
        return f"{SELF_DISARMED}: it heard no heartbeat from the PC for 1 s"
    return f"{SELF_DISARMED}: it reports {state.value}, with no fault"


def fell(end_reason: str | None, faults: list[str] | None) -> bool:
    """Whether a stored run ended in a fall: its end reason or its recorded faults say so (a run
    stored before the reasons were named: the old reason)."""
    if faults is not None and FELL in faults:
        return True
    reason = end_reason or ""
    return reason == LEGACY_SELF_DISARMED or reason.startswith(f"{FELL}:")


def end_safely(link) -> str:
    """A run's ending: DISARM confirmed by telemetry (:meth:`RobotLink.make_safe`), or why not — a
    lost link's robot disarms itself by its watchdog, and the supervisor disarms it when it is back."""
    try:
        return link.make_safe().value
    except LinkError as error:
        return f"not confirmed: {error}"


def robot_ending_record(end_reason: str | None, faults, telemetry: list[dict]) -> dict:
    """``robot_faults``: the robot's faults at the end, by name, and every one its telemetry reported
    during the run (``telemetry``: as a run stores it); ``fell``: whether the run ended in a fall (:func:`fell`)."""
    reported = set(faults)
    for entry in telemetry:
        reported.update(fault_names(int(entry.get("faults", 0))))
    names = sorted(reported)
    return {"robot_faults": names, "fell": fell(end_reason, names)}


class RunEnds(Exception):
    """A run's law ends it (:mod:`backend.robot.plan_law`): ``str(error)`` is the end reason."""
