"""scripts/virtual_robot_study.py's check in real time, end to end, as a lab member would do it.

``parkour serve`` and ``parkour robot-sim`` with hidden physics (the ``damped`` truth: ``--alpha 72
--c-zeta 1.25 --c-psi 0.8 --psi0-offset-deg 0.6 -0.8 --zeta0-offset 0.004 -0.005``, noise on),
driven through the REST API only: four open-loop runs of 40 jumps (the gaits of
``tests.tracked_climbs.VARIED_LEGS``), a calibration of them (``POST /api/v1/calibrations``), then
closed-loop runs of ``--jumps`` touchdowns to ``--target`` with the PID and the LQR designed on
the paper model, and the LQR designed on the calibration (``closed_loop.preset``). Each run's mean
|error| over its last 100 touchdowns and how it ended are printed. Real time: about 0.35 s a jump.

Usage: PYTHONPATH=. python scripts/virtual_robot_live.py [--runs 2] [--jumps 300] [--target 0.55]
"""

from __future__ import annotations

import argparse
import socket
import tempfile
import time
from pathlib import Path

import httpx
import numpy as np

from tests.helpers import free_port, start_robot_sim, start_service, stop_processes
from tests.tracked_climbs import VARIED_LEGS

TRUTH = ["--alpha", "72", "--c-zeta", "1.25", "--c-psi", "0.8", "--psi0-offset-deg", "0.6", "-0.8",
         "--zeta0-offset", "0.004", "-0.005"]  # fmt: skip
CASES = (("pid", None), ("lqr", None), ("lqr", "table"))


def run(api: httpx.Client, legs, jumps: int, closed_loop=None) -> dict:
    """One live run to its end; the stored run."""
    body = {"controls": [{"psi0_deg": p, "zeta0": z} for p, z in legs], "jumps": jumps, "max_seconds": 3600.0}
    if closed_loop is not None:
        body["closed_loop"] = closed_loop
    response = api.post("/api/v1/robot/runs", json=body)
    response.raise_for_status()
    while (status := api.get("/api/v1/robot").json())["run"]["active"]:
        time.sleep(0.5)
    api.post("/api/v1/robot/disarm")
    return api.get(f"/api/v1/runs/{status['run']['stored_run_id']}").json()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=2)
    parser.add_argument("--jumps", type=int, default=300)
    parser.add_argument("--target", type=float, default=0.55)
    args = parser.parse_args()
    data = Path(tempfile.mkdtemp(prefix="parkour-live-study-")) / "data"
    port, robot_port, tracker_port = free_port(), free_port(), free_port(socket.SOCK_DGRAM)
    service = start_service(data, port, "--view-port", "0")
    robot = start_robot_sim(robot_port, tracker_port, *TRUTH)
    token = (data / "api_token").read_text().strip()
    try:
        with httpx.Client(base_url=f"http://127.0.0.1:{port}", headers={"Authorization": f"Bearer {token}"},
                          timeout=30) as api:  # fmt: skip
            api.post("/api/v1/robot/connect", json={"url": f"socket://127.0.0.1:{robot_port}",
                                                    "tracker_port": tracker_port}).raise_for_status()  # fmt: skip
            open_loop = [run(api, legs, 40)["id"] for legs in VARIED_LEGS]
            fitted = api.post("/api/v1/calibrations", json={"runs": open_loop, "name": "table"})
            fitted.raise_for_status()
            params = fitted.json()["params"]
            print(f"calibrated from runs {open_loop}: {params}", flush=True)
            for controller, preset in CASES:
                for _ in range(args.runs):
                    loop = {"target_m": args.target, "controller": controller} | ({"preset": preset} if preset else {})
                    stored = run(api, ((35.0, 0.9), (35.0, 0.9)), args.jumps, loop)
                    heights = np.array([td["body_height"] for td in stored["results"]["touchdowns"]])
                    error = np.mean(np.abs(heights[-100:] - args.target)) if heights.size else float("nan")
                    print(f"{controller:>4} on {preset or 'paper':>5}: {heights.size} touchdowns, "
                          f"{stored['results']['end_reason']}, mean |error| of the last 100 {100 * error:.2f} cm",
                          flush=True)  # fmt: skip
    finally:
        stop_processes(robot, service)


if __name__ == "__main__":
    main()
