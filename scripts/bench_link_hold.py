"""Heartbeat gaps at the robot while the link's interpreter is held: the port in a thread, or in a radio process.

The link's heartbeat thread shares the service's interpreter; whatever holds its GIL — a compiled
kernel (numba's hold it for their whole call), a JSON encoder, a big C call — holds the heartbeat
too. This bench stands for a busy service with GIL holds drawn from one seeded schedule: holds of
``--hold-ms LOW,HIGH`` (uniform) at exponential intervals of mean ``--hold-every`` seconds, each a
C call that keeps the GIL (libc's ``usleep`` through ``ctypes.PyDLL``), beside ``--python-threads``
pure-Python busy threads. The same schedule runs twice, side by side: the link's port in this
interpreter (``RobotLink(radio_process=False)``, as before) and in a radio process
(``radio_process=True``, backend/robot/radio_process.py).

The robot (the virtual robot's firmware, radio only, its real 1 s watchdog) runs in a process of its
own (tests/robot_elsewhere.py) and notes when each of the PC's frames arrives, on the machine's
monotonic clock. Per mode: gaps between consecutive frames from the PC (any frame feeds the
watchdog; the PC sends one every 0.1 s; the phase's start and end count as frames, so a PC that
stops is a gap to the end) as bench_heartbeat.gaps_ms gives them — median, p99 (nearest rank),
max, how many exceed 150, 300 and 350 ms — and whether the robot disarmed itself (watchdog) during
the phase. Then the lease:
the radio process' service held for ``--lease-hold`` seconds (longer than the 0.5 s lease and the
robot's 1 s watchdog): the robot must disarm itself (``lease.robot_disarmed``).

Usage, from the checkout's root:

    PYTHONPATH=. python scripts/bench_link_hold.py [--seconds 20] [--hold-ms 50,400] [--hold-every 1.0]
        [--python-threads 4] [--lease-hold 2.0] [--seed 1] [--json]
"""

from __future__ import annotations

import argparse
import json
import random
import threading
import time

from backend.robot.link import RobotLink
from backend.robot.messages import Fault, RobotState
from scripts.bench_heartbeat import gaps_ms
from tests.robot_elsewhere import RobotElsewhere, hold_the_gil

WATCHDOG = 1.0  # [s] the robot's (firmware.HEARTBEAT_TIMEOUT)
SETTLE = 0.5  # [s] after arming, before the phase: the cadence (and a radio process' lease) running


def hold_schedule(seconds: float, low: float, high: float, every: float, seed: int) -> list[tuple[float, float]]:
    """(start from the phase's start [s], length [s]) of each hold: the same for every mode."""
    generator, holds, at = random.Random(seed), [], 0.0
    while True:
        at += generator.expovariate(1.0 / every)
        length = generator.uniform(low, high)
        if at + length > seconds:
            return holds
        holds.append((at, length))
        at += length


def busy(stop: threading.Event) -> None:
    while not stop.is_set():
        sum(i * i for i in range(2_000))


def phase(radio_process: bool, holds: list[tuple[float, float]], seconds: float, python_threads: int) -> dict:
    """One mode under the hold schedule: the robot's view of the PC's frames."""
    with RobotElsewhere(heartbeat_timeout=WATCHDOG) as robot:
        link = RobotLink(robot.url, radio_process=radio_process)
        stop = threading.Event()
        workers = [threading.Thread(target=busy, args=(stop,), daemon=True) for _ in range(python_threads)]
        try:
            link.connect(timeout=10.0)
            link.arm()
            time.sleep(SETTLE)
            start = time.monotonic()
            for worker in workers:
                worker.start()
            held = 0.0
            for at, length in holds:
                time.sleep(max(0.0, start + at - time.monotonic()))
                held += hold_the_gil(length)
            time.sleep(max(0.0, start + seconds - time.monotonic()))
            end = time.monotonic()
            stop.set()
            firmware = robot.firmware()
            arrivals = [start, *(t for t, _kind in robot.arrivals() if start <= t <= end), end]
        finally:
            stop.set()
            link.close()
    return {
        "port": "radio process" if radio_process else "thread (in the service's interpreter)",
        "frames": gaps_ms(arrivals),
        "holds": {
            "count": len(holds),
            "held_s": round(held, 2),
            "longest_ms": round(max((h for _, h in holds), default=0) * 1000),
        },
        "robot_state": RobotState(firmware.state).name.lower(),
        "link_transitions": [f"{t.before.value}->{t.after.value}: {t.reason}" for t in link.transitions],
        "robot_disarmed": firmware.state != RobotState.ARMED,
        "heartbeat_lost": bool(firmware.faults & Fault.HEARTBEAT_LOST),
    }


def lease(seconds: float) -> dict:
    """The radio process' service held longer than its lease and the robot's watchdog: the robot disarms."""
    with RobotElsewhere(heartbeat_timeout=WATCHDOG) as robot:
        link = RobotLink(robot.url, radio_process=True)
        try:
            link.connect(timeout=10.0)
            link.arm()
            time.sleep(SETTLE)
            start = time.monotonic()
            hold_the_gil(seconds)
            time.sleep(0.05)
            firmware = robot.firmware()
            after = [t for t, _kind in robot.arrivals() if t >= start]
        finally:
            link.close()
    during = [t - start for t in after if t < start + seconds]
    return {
        "held_s": seconds,
        "frames_during_hold": len(during),
        "last_frame_during_hold_s": round(during[-1], 3) if during else None,
        "robot_disarmed": firmware.state != RobotState.ARMED,
        "heartbeat_lost": bool(firmware.faults & Fault.HEARTBEAT_LOST),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seconds", type=float, default=20.0)
    parser.add_argument("--hold-ms", default="50,400", help="LOW,HIGH: each hold's length, uniform [ms]")
    parser.add_argument("--hold-every", type=float, default=1.0, help="mean seconds between holds (exponential)")
    parser.add_argument("--python-threads", type=int, default=4)
    parser.add_argument("--lease-hold", type=float, default=2.0)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args()
    low, high = (float(x) / 1000 for x in args.hold_ms.split(","))
    holds = hold_schedule(args.seconds, low, high, args.hold_every, args.seed)
    result = {
        "seconds": args.seconds,
        "schedule": {
            "holds": len(holds),
            "hold_ms": args.hold_ms,
            "hold_every_s": args.hold_every,
            "python_threads": args.python_threads,
            "seed": args.seed,
        },
        "thread": phase(False, holds, args.seconds, args.python_threads),
        "radio_process": phase(True, holds, args.seconds, args.python_threads),
        "lease": lease(args.lease_hold),
    }
    if args.json:
        print(json.dumps(result, indent=2))
        return
    for name in ("thread", "radio_process"):
        figures = result[name]
        print(f"{figures['port']}: frames at the robot {figures['frames']}; robot {figures['robot_state']}")
    print(f"lease: {result['lease']}")


if __name__ == "__main__":
    main()
