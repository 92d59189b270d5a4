"""A 300-jump calibrated-LQR live run under 20 clients of load, end to end: does it complete?

The lab's finding: one late SET_LEG acknowledgement (> 0.5 s) ended a run — a calibrated LQR run
holding at 10.7 mm RMS ended at touchdown 255, "no acknowledgement for SetLeg within 0.5 s" (300-jump
runs, 20 clients loading another service). The link now writes a command whose acknowledgement is
late again (the same seq, every 0.1 s; ``command_resends`` in ``GET /api/v1/robot``'s counters).

The service (``parkour serve --no-view``, SQLite in a temporary data directory, a free port) drives
the virtual robot (``parkour robot-sim``, noise on, seeded) whose hidden truth is ``--truth`` (one of
scripts/calibration_live_falls.py's TRUTHS, with its seed, or one of scripts/calibration_truths.py's,
seed 0), through the REST API only:

1. calibration: four open-loop live runs of ``--calibration-jumps`` touchdowns (the gaits of
   ``tests.tracked_climbs.VARIED_LEGS``; a fall is fine) and ``POST /api/v1/calibrations`` of them,
   stored as a preset; its fit against the truth is printed (error in standard errors), unloaded;
2. ``--runs`` times: ``--clients`` clients POST ``/api/v1/sim/map`` back to back from a process of
   their own (tests.helpers.start_map_load) — at this service, or with ``--load-service`` at a second
   ``parkour serve`` on this machine (as the lab did) — while ``POST /api/v1/robot/runs`` runs
   ``--jumps`` touchdowns closed loop: both legs start at psi0 35 deg, zeta0 0.9, the LQR designed
   on the calibration holds ``--target`` (``max_seconds`` ``--max-seconds``); waited for to its end.

Per run: the end reason ("jumps done": completed; otherwise it ended early, and a fall says so), the
stored status, touchdowns, the height error over the last 100 touchdowns (``GET /api/v1/runs/{id}``:
each touchdown's ``body_height`` against the target; RMS and mean, mm), the link's counters before
and after (``command_resends``, ``write_timeouts``, ``estops_unacknowledged``, and the radio's
``retries``, ``delivery_failures``, the supervisor's ``reconnects``), tracker gaps, the load's
answers, the machine's load average (``os.getloadavg``, sampled every 2 s during the run: mean and
max of the 1-minute figure) and the time taken. Real time: ~2 min of calibration (60 jumps) and
~3 min a 300-jump run.

Usage, from the checkout's root:

    PYTHONPATH=. python scripts/bench_live_lqr_load.py [--truth damped] [--seed N] [--clients 20]
        [--jumps 300] [--target 0.55] [--runs 1] [--load-service] [--calibration-jumps 60]
        [--max-seconds 400] [--json]

Exit status: 0 when every run completed its jumps, 1 when one ended early. A calibration run that
ends "error: …" stops the script with the service's log tail (scripts/calibration_live_falls.Api).
"""

from __future__ import annotations

import argparse
import json
import os
import socket
import sys
import tempfile
import threading
import time
from pathlib import Path

import numpy as np

from scripts.calibration_live_falls import TRUTHS as FALLS_TRUTHS
from scripts.calibration_live_falls import Api, compared, flat, run_row, sim_options, tail
from scripts.calibration_truths import TRUTHS as FIT_TRUTHS
from sim_core.calibration.fit import PARAMETERS
from tests.helpers import free_port, start_map_load, start_robot_sim, start_service, stop_map_load, stop_processes
from tests.tracked_climbs import VARIED_LEGS

# Every truth with its robot's seed: calibration_live_falls' own (seeded so that some open-loop gaits
# fall), and calibration_truths' (seed 0).
TRUTHS = {**{name: truth for name, (truth, _) in FALLS_TRUTHS.items()}, **FIT_TRUTHS}
SEEDS = {**{name: seed for name, (_, seed) in FALLS_TRUTHS.items()}, **dict.fromkeys(FIT_TRUTHS, 0)}
START_LEGS = ((35.0, 0.9), (35.0, 0.9))  # [left, right] (psi0_deg, zeta0): the closed loop's start
LAST = 100  # touchdowns the height error is taken over
COUNTERS = ("command_resends", "write_timeouts", "estops_unacknowledged", "retries", "delivery_failures",
            "reconnects", "frames_out")  # fmt: skip
LOAD_SAMPLE_S = 2.0  # [s] between load-average samples
POLL_S = 1.0  # [s] between polls of the run


class LoadAverage:
    """``os.getloadavg()`` sampled every LOAD_SAMPLE_S on a thread, from :meth:`start` to :meth:`stop`."""

    def __init__(self):
        self.samples: list[tuple[float, float, float]] = []
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._sample, name="loadavg", daemon=True)

    def start(self) -> LoadAverage:
        self._thread.start()
        return self

    def stop(self) -> dict:
        self._stop.set()
        self._thread.join()
        ones = [s[0] for s in self.samples]
        return {
            "mean_1min": round(float(np.mean(ones)), 2) if ones else None,
            "max_1min": round(max(ones), 2) if ones else None,
            "at_end": [round(v, 2) for v in os.getloadavg()],
            "samples": len(ones),
            "cpus": os.cpu_count(),
        }

    def _sample(self) -> None:
        while True:
            self.samples.append(os.getloadavg())
            if self._stop.wait(LOAD_SAMPLE_S):
                return


def counters(api: Api) -> dict:
    found = api.get("/api/v1/robot")["counters"] or {}
    return {name: found.get(name) for name in COUNTERS}


def calibrate(api: Api, truth_name: str, seed: int, jumps: int, *, quiet: bool) -> dict:
    """Four open-loop live runs and their calibration, stored as a preset: its name and fit."""
    runs = []
    for legs in VARIED_LEGS:
        run = run_row(api.live_run(legs, jumps), legs)
        runs.append(run)
        if not quiet:
            print(f"  open loop, run {run['id']} {legs}: {run['status']}, {run['touchdowns']} touchdowns, "
                  f"fell {run['fell']} — {run['end_reason']}", flush=True)  # fmt: skip
    name = f"load-{truth_name}-{seed}-{int(time.time())}"
    answer = api.post("/api/v1/calibrations", {"runs": [r["id"] for r in runs], "name": name}, ok=(200, 201)).json()
    params = compared(flat(answer["params"]), flat(answer["stderr"]), TRUTHS[truth_name])
    fit = {"preset": name, "runs": runs, "pairs": answer["touchdowns_used"], "noise": answer["noise"], "params": params}
    if not quiet:
        cells = []
        for p in PARAMETERS:
            row = params[p]
            error = f"{row['error']:+.1f}%" if p == "alpha" else f"{row['error']:+.2g}"
            sigmas = "—" if row["sigmas"] is None else f"{row['sigmas']:+.1f}σ"
            cells.append(f"{p} {row['value']:.4g} ({error}, {sigmas})")
        print(f"  calibration {name!r}, {fit['pairs']} pairs: " + "; ".join(cells), flush=True)
    return fit


def height_error(touchdowns: list[dict], target: float) -> dict:
    """The last LAST touchdowns' body height against ``target``: RMS and mean [mm], and how many."""
    heights = np.array([td["body_height"] for td in touchdowns[-LAST:]], dtype=float)
    if not heights.size:
        return {"n": 0, "rms_mm": None, "mean_mm": None}
    errors = 1000.0 * (heights - target)
    return {"n": int(heights.size), "rms_mm": round(float(np.sqrt(np.mean(errors**2))), 2),
            "mean_mm": round(float(np.mean(errors)), 2)}  # fmt: skip


def loaded_run(api: Api, options, preset: str, load_base: str) -> dict:
    """One closed-loop run under ``options.clients`` clients loading ``load_base``; its record."""
    api.clear_estop()
    before = counters(api)
    load = start_map_load(load_base, options.clients) if options.clients else None
    loadavg = LoadAverage().start()
    began = time.monotonic()
    body = {"controls": [{"psi0_deg": p, "zeta0": z} for p, z in START_LEGS], "jumps": options.jumps,
            "max_seconds": options.max_seconds, "operator": "bench_live_lqr_load",
            "closed_loop": {"target_m": options.target, "controller": "lqr", "preset": preset}}  # fmt: skip
    try:
        run_id = api.post("/api/v1/robot/runs", body, ok=(202,)).json()["run"]["id"]
        deadline = time.monotonic() + options.max_seconds + 120.0
        while (status := api.get("/api/v1/robot"))["run"]["active"] or status["run"]["id"] != run_id:
            if time.monotonic() > deadline:
                raise SystemExit(f"run {run_id} did not end in {options.max_seconds + 120:g} s:\n{tail(api.log)}")
            time.sleep(POLL_S)
        seconds = time.monotonic() - began
    finally:
        average = loadavg.stop()
        answered = stop_map_load(load) if load is not None else {}
    after = counters(api)
    stored = api.get(f"/api/v1/runs/{run_id}")
    results = stored["results"]
    touchdowns = results.get("touchdowns") or []
    end_reason = results.get("end_reason") or status["run"]["end_reason"]
    if status["state"] == "estopped" or status["run"]["end_reason"] == "e-stop":
        api.clear_estop()
    return {
        "id": run_id, "status": stored["status"], "end_reason": end_reason,
        "completed": end_reason == "jumps done", "fell": results.get("fell"),
        "robot_faults": results.get("robot_faults"), "disarm": results.get("disarm"),
        "touchdowns": len(touchdowns), "commands": len(results.get("commands") or []),
        "height_error": height_error(touchdowns, options.target),
        "tracker_gaps": len(results.get("tracker_gaps") or []),
        "longest_tracker_gap_ms": status["run"].get("longest_tracker_gap_ms"),
        "counters_before": before, "counters_after": after,
        "counters_delta": {k: None if before[k] is None or after[k] is None else after[k] - before[k]
                           for k in COUNTERS},
        "load_answered": answered, "load_requests_per_s": round(sum(answered.values()) / seconds, 1),
        "loadavg": average, "seconds": round(seconds, 1),
    }  # fmt: skip


def report(row: dict, target: float, jumps: int) -> str:
    error = row["height_error"]
    rms = "—" if error["rms_mm"] is None else f"{error['rms_mm']:.1f}"
    mean = "—" if error["mean_mm"] is None else f"{error['mean_mm']:+.1f}"
    ending = "completed" if row["completed"] else ("ENDED EARLY: FELL" if row["fell"] else "ENDED EARLY")
    delta = row["counters_delta"]
    lines = [
        f"run {row['id']}: {ending} — {row['end_reason']!r}; stored {row['status']}; touchdowns "
        f"{row['touchdowns']} of {jumps}; {row['commands']} commands; disarm {row['disarm']}; faults "
        f"{row['robot_faults']}; {row['seconds']:.0f} s",
        f"  height error, last {error['n']} touchdowns vs {target:g} m: RMS {rms} mm, mean {mean} mm",
        "  link counters (before -> after, +delta): "
        + ", ".join(f"{k} {row['counters_before'][k]} -> {row['counters_after'][k]} (+{delta[k]})" for k in COUNTERS),
        f"  tracker gaps {row['tracker_gaps']} (longest {row['longest_tracker_gap_ms']} ms); load answered "
        f"{row['load_answered']} ({row['load_requests_per_s']}/s); load average 1-min mean "
        f"{row['loadavg']['mean_1min']}, max {row['loadavg']['max_1min']} ({row['loadavg']['cpus']} CPUs; "
        f"at the end {row['loadavg']['at_end']})",
    ]
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--truth", choices=list(TRUTHS), default="damped", help="the virtual robot's hidden truth")
    parser.add_argument("--seed", type=int, help="the virtual robot's seed (default: the truth's own)")
    parser.add_argument("--clients", type=int, default=20, help="clients POSTing /sim/map (0: no load)")
    parser.add_argument("--load-service", action="store_true", help="load a second service, not the robot's")
    parser.add_argument("--jumps", type=int, default=300, help="touchdowns the closed-loop run asks for")
    parser.add_argument("--target", type=float, default=0.55, help="the height the LQR holds [m]")
    parser.add_argument("--max-seconds", type=float, default=400.0, help="the closed-loop run's time limit [s]")
    parser.add_argument("--runs", type=int, default=1, help="closed-loop runs, one after another")
    parser.add_argument("--calibration-jumps", type=int, default=60, help="touchdowns of each open-loop run")
    parser.add_argument("--json", action="store_true")
    options = parser.parse_args()
    seed = SEEDS[options.truth] if options.seed is None else options.seed
    quiet = options.json
    began = time.monotonic()
    data = Path(tempfile.mkdtemp(prefix="parkour-lqr-load-"))
    log = data / "service.log"
    port, robot_port, tracker_port = free_port(), free_port(), free_port(socket.SOCK_DGRAM)
    service = start_service(data / "data", port, "--no-view", log=log)
    processes = [service]
    rows: list[dict] = []
    try:
        base = f"http://127.0.0.1:{port}"
        load_base = base
        if options.load_service:
            other_port = free_port()
            processes.append(start_service(data / "other", other_port, "--no-view", log=data / "other.log"))
            load_base = f"http://127.0.0.1:{other_port}"
        api = Api(base, (data / "data" / "api_token").read_text().strip(), log)
        argv = sim_options(TRUTHS[options.truth], seed)
        if not quiet:
            print(f"{options.truth}: parkour robot-sim {' '.join(argv)}; service log {log}", flush=True)
        processes.append(start_robot_sim(robot_port, tracker_port, *argv))
        api.connect(robot_port, tracker_port)
        fit = calibrate(api, options.truth, seed, options.calibration_jumps, quiet=quiet)
        calibrated_s = round(time.monotonic() - began, 1)
        if not quiet:
            where = f"a second service ({load_base})" if options.load_service else "this service"
            print(f"calibrated in {calibrated_s:.0f} s; {options.runs} run(s) of {options.jumps} jumps, lqr on "
                  f"{fit['preset']!r} to {options.target:g} m, {options.clients} clients loading {where}",
                  flush=True)  # fmt: skip
        for _ in range(options.runs):
            row = loaded_run(api, options, fit["preset"], load_base)
            rows.append(row)
            if not quiet:
                print(report(row, options.target, options.jumps), flush=True)
        api.post("/api/v1/robot/disconnect", ok=(200, 409))
    finally:
        stop_processes(*reversed(processes))
    completed = sum(row["completed"] for row in rows)
    total = round(time.monotonic() - began, 1)
    if options.json:
        print(json.dumps({"truth": options.truth, "seed": seed, "clients": options.clients,
                          "load_service": options.load_service, "jumps": options.jumps, "target": options.target,
                          "calibration": fit, "calibration_seconds": calibrated_s, "runs": rows,
                          "completed": completed, "seconds": total}, indent=1))  # fmt: skip
    else:
        rms = [row["height_error"]["rms_mm"] for row in rows if row["completed"]]
        held = f"; RMS of the completed: {', '.join(f'{v:.1f}' for v in rms)} mm" if rms else ""
        print(f"{completed} of {len(rows)} run(s) completed {options.jumps} jumps{held}; total {total:.0f} s")
    sys.exit(0 if completed == len(rows) else 1)


if __name__ == "__main__":
    main()
