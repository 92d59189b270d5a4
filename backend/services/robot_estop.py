"""The e-stop press: the robot first, then the disk, then the answer.

A press latches whether or not a robot is connected (:class:`~backend.robot.latch.EstopLatch`):
with no link, the next connect sends ESTOP before anything else and ARM, START and live runs are
refused until a RESET the robot acknowledges. With a link, the ESTOP goes out at once
(:meth:`RobotLink.estop`: the latch is engaged without waiting for a disk); only then does the
press wait, at most :data:`LATCH_SAVE_WAIT`, for the latch file, so an answer that says
``latched`` with ``durable`` true survives a kill -9 right after it. A disk that is slow or full
is said in the answer (``durable`` false and why), never a reason to delay the robot's stop.
"""

from __future__ import annotations

from backend.robot.latch import EstopLatch
from backend.robot.link import EstopResult, LinkState, RobotLink

NOT_CONNECTED_LATCH = (
    "emergency stop, no robot connected: the next connect sends it before anything else; it holds until a reset"
)
LATCH_SAVE_WAIT = 0.5  # [s] the longest a press waits for the latch file after the ESTOP went out
NOT_CONNECTED = (
    "the robot is not connected: the e-stop latch holds, and the next connect sends ESTOP before anything else"
)


def press(latch: EstopLatch, link: RobotLink | None, run, by: str | None = None) -> dict:
    """Stop ``run`` (a live run, or None), e-stop the robot on ``link`` (None: latch only), note who
    pressed it (``by``), then wait for the latch file. ``acknowledged``, ``latency_ms`` and, when not
    acknowledged, ``reason``."""
    if run is not None and not run.done.is_set():
        run.stop("e-stop")  # before the e-stop: the control loop sends nothing more
    if link is None:
        latch.engage()
        result = EstopResult(False, 0.0, NOT_CONNECTED)
    else:
        result = link.estop()
    if by is not None:
        latch.attribute(by)  # after the robot's ESTOP: who pressed it never delays it
    latch.flush(LATCH_SAVE_WAIT)  # after the robot's ESTOP: the robot never waits for the disk
    answer = {"acknowledged": result.acknowledged, "latency_ms": result.latency * 1000.0}
    if not result.acknowledged:
        answer["reason"] = result.reason
    return answer


def latch_status(latch: EstopLatch, link: RobotLink | None) -> dict:
    """The e-stop latch for the status: held until a RESET is acknowledged (``acknowledged``: the
    robot has confirmed the ESTOP on this connection; until then it goes in place of heartbeats;
    ``durable``: the latch as it is now is in its file). A robot that reports itself e-stopped is
    latched on its side whatever the PC's latch says."""
    state = latch.state
    if not state.held and link is not None and link.state == LinkState.ESTOPPED:
        return {"latched": True, "acknowledged": True, "since": None, "durable": state.durable,
                "reason": "the robot reports itself e-stopped; it holds until a reset", **_who(state)}  # fmt: skip
    reason = state.reason()
    if state.pending and (link is None or link.state == LinkState.DISCONNECTED):
        reason = NOT_CONNECTED_LATCH
    if state.held and not state.durable:
        failed = latch.save_error
        reason += f"; not saved, a restart would forget it ({failed})" if failed else "; being saved"
    return {
        "latched": state.held,
        "acknowledged": state.acknowledged,
        "since": state.since,
        "durable": state.durable,
        "reason": reason,
        **_who(state),
    }


def _who(state) -> dict:
    return {"pressed_by": state.pressed_by, "reset_by": state.reset_by, "reset_at": state.reset_at}
