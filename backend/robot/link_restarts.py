"""A restart of the robot, as its telemetry shows it (docs/protocol.md §3).

The firmware sets BOOTED at every boot (power-up, brown-out, reset) until the PC's first ARM, and
its sequence starts again at 1. A TELEMETRY carrying BOOTED is a restart when the one heard before
it (by the same link, on this connection or the last) did not carry it — the robot had been armed
since its last boot — or when the robot's sequence went back: a second boot before any ARM. The
first telemetry a link ever hears is no restart: a robot just switched on is not one that restarted
under us. A sequence that went back without BOOTED is not taken for a restart: that is a late,
stale or forged frame; a real boot always sets BOOTED.
"""

from __future__ import annotations

from backend.robot.messages import Fault, Telemetry

SEQ_WINDOW = 16  # a sequence this far behind the last one or nearer: a late frame, not a restart
# A restarted robot's sequence is this small or smaller: some 60 s of its traffic (telemetry every
# 0.1 s, heartbeats every 0.2 s), more than it can send before the PC hears it after a boot.
BOOT_SEQ = 1024


def went_back(last: int, seq: int) -> bool:
    """Whether the 16-bit sequence ``seq`` went back from ``last`` as a boot's does: behind it by more
    than the window (a wrap goes forward) and near the start."""
    behind = (last - seq) & 0xFFFF
    return SEQ_WINDOW < behind < 0x8000 and seq <= BOOT_SEQ


def restart_reason(previous: Telemetry | None, telemetry: Telemetry) -> str | None:
    """Why ``telemetry`` shows a restart of the robot since ``previous`` (the last one heard; None:
    the first), in the operator's words — ``robot restarted (brown-out; its sequence went back from
    4211 to 2)`` — or None."""
    if previous is None or not telemetry.faults & Fault.BOOTED:
        return None
    back = went_back(previous.seq, telemetry.seq)
    if previous.faults & Fault.BOOTED and not back:
        return None  # the same boot, still not armed
    details = ["brown-out"] if telemetry.faults & Fault.BROWNOUT else []
    if back:
        details.append(f"its sequence went back from {previous.seq} to {telemetry.seq}")
    return f"robot restarted ({'; '.join(details or ['it reports having just booted'])})"
