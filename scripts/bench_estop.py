"""E-stop latency, end to end: PC link -> TCP -> virtual robot firmware -> acknowledgement back.

Usage: python scripts/bench_estop.py [--repeats 100] [--json]
"""

from __future__ import annotations

import argparse
import json
import statistics

from backend.robot.link import RobotLink
from backend.robot.virtual import VirtualRobot


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=100)
    parser.add_argument("--json", action="store_true")
    options = parser.parse_args()
    robot = VirtualRobot().start()
    link = RobotLink(robot.url)
    link.connect()
    latencies = []
    try:
        for _ in range(options.repeats):
            link.arm()
            result = link.estop()
            if not result.acknowledged:
                raise SystemExit(f"e-stop not acknowledged: {result.reason}")
            latencies.append(result.latency * 1000)
            link.reset()
    finally:
        link.close()
        robot.stop()
    latencies.sort()
    result = {
        "repeats": options.repeats,
        "p50_ms": statistics.median(latencies),
        "p95_ms": latencies[int(0.95 * (len(latencies) - 1))],
        "p99_ms": latencies[int(0.99 * (len(latencies) - 1))],
        "max_ms": latencies[-1],
        "frames_rejected": link.parser.stats.bad_checksum + link.rejected_payloads,
    }
    if options.json:
        print(json.dumps(result))
    else:
        print(
            f"e-stop to acknowledgement over {options.repeats} runs: p50 {result['p50_ms']:.2f} ms, "
            f"p95 {result['p95_ms']:.2f} ms, p99 {result['p99_ms']:.2f} ms, max {result['max_ms']:.2f} ms"
        )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
