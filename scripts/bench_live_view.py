"""The 3D view in live mode during live runs: bytes and updates per second reaching each browser.

Starts the service (``parkour serve``, its view on a free port) and the virtual robot
(``parkour robot-sim``, streaming its 100 Hz tracker datagrams to the service), connects the
robot, opens ``--browsers`` headless browsers (websocket clients that speak to the view as
viser's web client does: tests/frontend/viewer/headless.py) and puts each in live mode through
its Mode dropdown, as a person would. Then it makes ``--runs`` live runs of ``--jumps`` jumps
one after another (the trail is drawn afresh at each run's start) and reports, for each run,
per browser: kB/s, updates/s (websocket messages), the mean and largest update; and the frames
per second the view's loop drew (for each browser: the rate it reports) and the service's CPU.

``--screenshot PATH`` adds one real browser (headless Chromium, SwiftShader WebGL), puts it in
live mode through its Mode dropdown and saves a PNG of it ``SHOT_AT_S`` into the last run (its
figures are then not those of ``--browsers`` alone: report them without it).

``--tree PATH`` runs the service from another checkout (this one's scripts and venv): measure a
base revision with ``git worktree add /tmp/base HEAD`` before a change.

    PYTHONPATH=. .venv/bin/python scripts/bench_live_view.py [--browsers 2] [--jumps 40] [--runs 2]
"""

from __future__ import annotations

import argparse
import contextlib
import json
import os
import shutil
import socket
import tempfile
import time
from pathlib import Path

import httpx

from tests.frontend.viewer.headless import HeadlessViewer
from tests.helpers import free_port, start_robot_sim, start_service, stop_processes

CONTROLS = [{"psi0_deg": 30, "zeta0": 0.87}, {"psi0_deg": 30, "zeta0": 0.9}]  # a steady climb
SETTLE_S = 2.0  # [s] after the browsers join, before the first run: their first scene is sent
BETWEEN_RUNS_S = 1.0  # [s] the robot stands still between runs
SHOT_AT_S = 8.0  # [s] into the last run: some jumps up, the trail at its full length soon
POLL_S = 0.5  # [s] between asks whether the run has ended (and the loop's rate): little load


def _cpu_seconds(pid: int) -> float:
    """CPU time [s] process ``pid`` has used so far (Linux /proc)."""
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def _wait(condition, timeout: float, what: str, period: float = 0.05) -> None:
    deadline = time.monotonic() + timeout
    while not condition():
        if time.monotonic() > deadline:
            raise TimeoutError(what)
        time.sleep(period)


@contextlib.contextmanager
def _chromium_in_live_mode(port: int):
    """A headless Chromium page on the view, switched to live mode as a person would."""
    from playwright.sync_api import sync_playwright

    with sync_playwright() as playwright:
        software_webgl = ["--no-sandbox", "--use-angle=swiftshader", "--enable-unsafe-swiftshader"]
        browser = playwright.chromium.launch(executable_path=shutil.which("chromium"), args=software_webgl)
        try:
            page = browser.new_page(viewport={"width": 1280, "height": 800})
            page.goto(f"http://127.0.0.1:{port}/")
            page.wait_for_selector("canvas", timeout=60_000)
            page.locator("text=Gait of these controls").wait_for(timeout=60_000)
            page.get_by_role("combobox", name="Mode").click()
            page.get_by_role("option", name="live").click()
            page.locator("text=Touchdowns this run").wait_for(timeout=30_000)
            yield page
        finally:
            browser.close()


def _per_browser(viewer: HeadlessViewer, start: float, end: float) -> dict:
    sizes = [size for t, size in zip(viewer.arrivals, viewer.sizes, strict=False) if start <= t < end]
    seconds = end - start
    return {
        "kb_per_s": sum(sizes) / 1000 / seconds,
        "updates_per_s": len(sizes) / seconds,
        "mean_update_kb": sum(sizes) / 1000 / max(len(sizes), 1),
        "largest_update_kb": max(sizes, default=0) / 1000,
    }


def measure(
    browsers: int, jumps: int, runs: int, noise: str, tree: Path | None, screenshot: Path | None = None
) -> list[dict]:
    """One result per run: its seconds, touchdowns, the loop's frames/s, the service's CPU [cores]
    and each browser's figures; ``screenshot``: where Chromium's picture of the last run goes."""
    with tempfile.TemporaryDirectory() as tmp:
        data, api_port, view_port = Path(tmp) / "data", free_port(), free_port()
        service = start_service(data, api_port, "--view-port", str(view_port), tree=tree)
        robot_port, tracker_port = free_port(), free_port(socket.SOCK_DGRAM)
        robot = start_robot_sim(robot_port, tracker_port, "--noise", noise)
        viewers: list[HeadlessViewer] = []
        stack = contextlib.ExitStack()
        token = (data / "api_token").read_text().strip()
        api = httpx.Client(base_url=f"http://127.0.0.1:{api_port}", headers={"Authorization": f"Bearer {token}"})
        try:
            connect = {"url": f"socket://127.0.0.1:{robot_port}", "tracker_port": tracker_port}
            api.post("/api/v1/robot/connect", json=connect, timeout=30).raise_for_status()
            port = api.get("/api/v1/view").json()["port"]
            viewers = [HeadlessViewer(port, f"bench-live-{i}") for i in range(browsers)]

            def all_live() -> bool:
                # The Mode dropdown reaches a browser before the view listens to it, and viser
                # calls back only on a change: choose simulate, then live, until it has listened.
                modes = [api.get("/api/v1/view", params={"viewer": f"bench-live-{i}"}).json()["mode"]
                         for i in range(browsers)]  # fmt: skip
                for viewer, mode in zip(viewers, modes, strict=True):
                    if mode != "live":
                        viewer.set_gui("Mode", "simulate")
                        viewer.set_gui("Mode", "live")
                time.sleep(0.2)
                return modes == ["live"] * browsers

            _wait(all_live, 30, "the browsers did not reach live mode")
            page = stack.enter_context(_chromium_in_live_mode(port)) if screenshot else None
            time.sleep(SETTLE_S)
            results = []
            for k in range(runs):
                cpu, start = _cpu_seconds(service.pid), time.monotonic()
                body = {"controls": CONTROLS, "jumps": jumps, "max_seconds": 10.0 + 2.0 * jumps}
                api.post("/api/v1/robot/runs", json=body).raise_for_status()
                loop_rates = []  # the view's loop: frames drawn per second (for each browser)

                shoot = page is not None and k == runs - 1

                def ended(loop_rates=loop_rates, start=start, shoot=shoot) -> bool:
                    loop_rates.append(api.get("/api/v1/view").json()["updates_per_s"])
                    if shoot and time.monotonic() - start >= SHOT_AT_S and not screenshot.exists():
                        page.screenshot(path=str(screenshot))
                    return not api.get("/api/v1/robot").json()["run"]["active"]

                _wait(ended, 30 + 2 * jumps, "the run did not end", period=POLL_S)
                end = time.monotonic()
                run = api.get("/api/v1/robot").json()["run"]
                results.append({
                    "seconds": end - start,
                    "touchdowns": run["touchdowns"],
                    "end_reason": run["end_reason"],
                    "cpu_cores": (_cpu_seconds(service.pid) - cpu) / (end - start),
                    "loop_frames_per_s": sum(loop_rates) / len(loop_rates),
                    "browsers": [_per_browser(viewer, start, end) for viewer in viewers],
                })  # fmt: skip
                time.sleep(BETWEEN_RUNS_S)
            return results
        finally:
            stack.close()
            for viewer in viewers:
                viewer.close()
            api.close()
            stop_processes(robot, service)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--browsers", type=int, default=2)
    parser.add_argument("--jumps", type=int, default=40, help="touchdowns per run")
    parser.add_argument("--runs", type=int, default=2, help="runs one after another")
    parser.add_argument("--noise", choices=("off", "on"), default="off", help="the virtual robot's noise")
    parser.add_argument("--tree", type=Path, help="run the service from this checkout (a base revision)")
    parser.add_argument("--screenshot", type=Path, help="add Chromium in live mode; a PNG of the last run here")
    parser.add_argument("--json", action="store_true", help="print the results as JSON")
    args = parser.parse_args()
    if args.screenshot is not None:
        args.screenshot.unlink(missing_ok=True)
    results = measure(args.browsers, args.jumps, args.runs, args.noise, args.tree, args.screenshot)
    if args.json:
        print(json.dumps(results, indent=1))
        return
    print("run | seconds | touchdowns | CPU [cores] | loop frames/s | browser | kB/s | updates/s | mean update [kB] "
          "| largest [kB]")  # fmt: skip
    for k, run in enumerate(results, start=1):
        for b, each in enumerate(run["browsers"], start=1):
            print(
                f"{k:3d} | {run['seconds']:7.1f} | {run['touchdowns']:10d} | {run['cpu_cores']:11.2f} | "
                f"{run['loop_frames_per_s']:13.1f} | {b:7d} | "
                f"{each['kb_per_s']:6.1f} | {each['updates_per_s']:9.1f} | {each['mean_update_kb']:16.2f} | "
                f"{each['largest_update_kb']:12.1f}"
            )


if __name__ == "__main__":
    main()
