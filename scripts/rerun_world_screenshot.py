"""A robot run in a random-foothold world, exported as MCAP, opened in Rerun: its entity list and a screenshot.

Starts ``parkour serve`` and the virtual robot (``parkour robot-sim --world FILE --noise off``) on
a fresh data directory, stores ``random_world(--seed)`` (``POST /api/v1/worlds``; the robot climbs
the same world, written to FILE), plans a climb to ``--goal`` in it (a ``plan`` job, from the first
leg's gait) and follows the plan (``POST /api/v1/robot/runs`` with its ``plan_job_id``, in real time:
the placement law sends each next leg; open loop where no plan reaches the goal), exports the
stored run (``parkour export``), converts it with Rerun's MCAP importer (``rerun mcap convert``, its
default decoders), prints the entities (path, timed rows, components by archetype) and writes them
to entities.txt beside the .rrd, then opens the .rrd in Rerun's web viewer (served here) in headless
Chromium (WebGL2 from SwiftShader: no GPU) with a blueprint: a 3D view of ``/world`` and
``/tracker`` (the world's points, the body's path, its last pose as axes) beside the height plot.
The screenshot is taken once the page stops changing, at most ``--wait`` seconds (35-50 s here, 2 cores).

Usage: PYTHONPATH=. python scripts/rerun_world_screenshot.py [--seed 5] [--jumps 40] [--goal 1.5]
    [--out docs/screenshots/rerun_world.png] [--size 1400x900] [--wait 60] [--keep DIR]
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import socket
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import httpx
import rerun as rr
import rerun.blueprint as rrb
from playwright.sync_api import sync_playwright
from rerun.chunk import RrdReader

from tests.helpers import free_port, start_robot_sim, start_service, stop_processes

LEGS = ((35.0, 0.94), (35.0, 0.94))  # random 5: about five jumps before a fall (open loop)
APP = "parkourlab_world"  # the .rrd's application id, which the blueprint names
# Headless Chromium has no GPU here: WebGL2 from SwiftShader (Rerun falls back from WebGPU to it).
CHROMIUM_FLAGS = ["--use-angle=swiftshader", "--enable-unsafe-swiftshader", "--ignore-gpu-blocklist", "--enable-webgl"]
FILES = "http://recording.invalid/"  # the page's fetches of the .rrd and .rbl, answered by Playwright
ENV = {**os.environ, "CI": "true"}  # Rerun sends no usage data and asks nothing on a first run


def robot_run_in_world(data: Path, seed: int, jumps: int, goal_m: float) -> int:
    """The stored run's id: the virtual robot climbing the stored world ``random_world(seed)``,
    following a plan job's plan to ``goal_m`` [m] (open loop where the planner finds none)."""
    port, robot_port, tracker_port = free_port(), free_port(), free_port(socket.SOCK_DGRAM)
    service = start_service(data, port, "--view-port", "0")
    robot = None
    token = (data / "api_token").read_text().strip()
    try:
        with httpx.Client(base_url=f"http://127.0.0.1:{port}", headers={"Authorization": f"Bearer {token}"},
                          timeout=60) as api:  # fmt: skip
            world = api.post("/api/v1/worlds", json={"name": f"random {seed}", "random": {"seed": seed}})
            world.raise_for_status()
            world_file = data / "world.json"
            world_file.write_text(json.dumps(world.json()["world"]))
            robot = start_robot_sim(robot_port, tracker_port, "--world", str(world_file), "--noise", "off")
            api.post("/api/v1/robot/connect", json={"url": f"socket://127.0.0.1:{robot_port}",
                                                    "tracker_port": tracker_port}).raise_for_status()  # fmt: skip
            plan = {"kind": "plan", "world_id": world.json()["id"], "goal_height_m": goal_m, "launch_gait": True}
            job = api.post("/api/v1/jobs", json=plan).raise_for_status().json()["id"]
            while (state := api.get(f"/api/v1/jobs/{job}").json()["state"]) in ("queued", "running"):
                time.sleep(0.5)
            result = api.get(f"/api/v1/jobs/{job}/results").json()["result"]
            if state == "done" and result["reaches_goal"]:  # the run follows the plan (the placement law)
                body = {"plan_job_id": job, "jumps": jumps, "max_seconds": 600.0}
            else:  # no plan to the goal in this world: the open-loop gait, which falls after a few jumps
                print(f"plan job {job} {state}, no plan to {goal_m} m: climbing open loop")
                body = {"controls": [{"psi0_deg": p, "zeta0": z} for p, z in LEGS], "jumps": jumps,
                        "world_id": world.json()["id"], "max_seconds": 600.0}  # fmt: skip
            api.post("/api/v1/robot/runs", json=body).raise_for_status()
            while (status := api.get("/api/v1/robot").json())["run"]["active"]:
                time.sleep(0.5)
            api.post("/api/v1/robot/disarm")
            run = api.get(f"/api/v1/runs/{status['run']['stored_run_id']}").json()
            print(f"run {run['id']} in world {world.json()['id']} (random {seed}): "
                  f"{len(run['results']['touchdowns'])} touchdowns, {run['results']['end_reason']}")  # fmt: skip
            return run["id"]
    finally:
        stop_processes(*([robot] if robot else []), service)


def entity_listing(rrd: Path) -> list[str]:
    """One line per entity: its path, its timed rows (a topic's messages; the static row of its
    MCAP channel and schema not counted) and its components by archetype (but McapChannel and
    McapSchema, which every topic has)."""
    components: dict[str, dict[str, set[str]]] = {}
    rows: dict[str, int] = {}
    for chunk in RrdReader(rrd).stream():
        batch = chunk.to_record_batch()
        rows[chunk.entity_path] = rows.get(chunk.entity_path, 0) + (0 if chunk.is_static else batch.num_rows)
        found = components.setdefault(chunk.entity_path, {})
        for field in batch.schema:
            meta = field.metadata or {}
            archetype, _, name = field.name.rpartition(":")
            archetype = archetype or meta.get(b"rerun:archetype", b"").decode()
            if meta.get(b"rerun:kind") == b"data" and archetype not in ("McapChannel", "McapSchema"):
                found.setdefault(archetype, set()).add(name)
    return [
        f"{path}  ({rows[path]} timed rows)  "
        + "; ".join(f"{kind}: {', '.join(sorted(names))}" for kind, names in sorted(found.items()))
        for path, found in sorted(components.items())
    ]


def blueprint() -> rrb.Blueprint:
    """The world's points, the body's path (every frame up to the time cursor) and its pose (axes)
    in 3D, beside the height plot; the blueprint tree open, the selection and time panels closed."""
    eye = rrb.EyeControls3D(position=(0.5, -2.1, 1.0), look_target=(0.0, 0.0, 0.95), eye_up=(0.0, 0.0, 1.0))
    path = rrb.VisibleTimeRanges(timeline="message_log_time", start=rr.TimeRangeBoundary.infinite(),
                                 end=rr.TimeRangeBoundary.cursor_relative())  # fmt: skip
    axes = {"/tracker/transform": rr.TransformAxes3D(axis_length=0.1).visualizer()}
    chute = rrb.Spatial3DView(name="chute: /world/points and the body", contents=["/world/**", "/tracker/**"],
                              eye_controls=eye, time_ranges=path, overrides=axes)  # fmt: skip
    heights = ["/plot/height", "/plot/touchdown/body_height", "/plot/touchdown/foot_height"]
    plots = rrb.TimeSeriesView(name="height [m]", origin="/plot", contents=heights)
    return rrb.Blueprint(rrb.Horizontal(chute, plots, column_shares=[3, 2]), rrb.BlueprintPanel(state="expanded"),
                         rrb.SelectionPanel(state="collapsed"), rrb.TimePanel(state="collapsed"),
                         auto_views=False)  # fmt: skip


def screenshot(files: dict[str, bytes], out: Path, width: int, height: int, wait: float) -> None:
    """Rerun's web viewer (served here) in headless Chromium, opening ``files`` (fetched from
    :data:`FILES`, answered by Playwright); a screenshot once two taken 3 s apart are the same (not
    before 15 s), or the last one at ``wait`` seconds."""
    port = free_port()
    rr.serve_web_viewer(web_port=port, open_browser=False)
    query = "&".join(f"url={FILES}{name}" for name in files)
    with sync_playwright() as playwright:
        browser = playwright.chromium.launch(executable_path=shutil.which("chromium"), args=CHROMIUM_FLAGS)
        try:
            page = browser.new_page(viewport={"width": width, "height": height})
            cors = {"Access-Control-Allow-Origin": "*"}
            page.route(
                f"{FILES}*", lambda route: route.fulfill(body=files[route.request.url[len(FILES) :]], headers=cors)
            )
            page.goto(f"http://127.0.0.1:{port}/?{query}")
            started, last, stable = time.monotonic(), None, False
            while not stable and time.monotonic() - started < wait:
                time.sleep(3.0)
                picture = page.screenshot()
                stable, last = picture == last and time.monotonic() - started > 15.0, picture
            out.parent.mkdir(parents=True, exist_ok=True)
            out.write_bytes(last)
            print(f"{out}: after {time.monotonic() - started:.0f} s" + ("" if stable else " (still changing)"))
        finally:
            browser.close()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seed", type=int, default=5)
    parser.add_argument("--jumps", type=int, default=40)
    parser.add_argument("--goal", type=float, default=1.5, help="[m] the plan's goal height")
    parser.add_argument("--out", type=Path, default=Path("docs/screenshots/rerun_world.png"))
    parser.add_argument("--size", default="1400x900", help="the browser's viewport, WIDTHxHEIGHT")
    parser.add_argument("--wait", type=float, default=60.0, help="[s] at most, for the viewer to draw the recording")
    parser.add_argument(
        "--keep", type=Path, help="the data dir, .mcap, .rrd, .rbl and entities.txt here (default: temp)"
    )
    args = parser.parse_args()
    work = args.keep or Path(tempfile.mkdtemp(prefix="parkour-rerun-world-"))
    work.mkdir(parents=True, exist_ok=True)
    data, mcap, rrd, rbl = work / "data", work / "run.mcap", work / "run.rrd", work / "view.rbl"
    run_id = robot_run_in_world(data, args.seed, args.jumps, args.goal)
    cli = [sys.executable, "-m", "cli", "export", str(run_id), "--out", str(mcap), "--data-dir", str(data)]
    subprocess.run(cli, check=True)
    convert = [sys.executable, "-m", "rerun_cli", "mcap", "convert", str(mcap), "-o", str(rrd), "--application-id", APP]
    subprocess.run(convert, check=True, env=ENV, capture_output=True)
    listing = entity_listing(rrd)
    (work / "entities.txt").write_text("\n".join(listing) + "\n")
    print(f"{rrd}: {len(listing)} entities (also in {work / 'entities.txt'})", *listing, sep="\n")
    blueprint().save(APP, rbl)
    width, height = map(int, args.size.split("x"))
    screenshot({"run.rrd": rrd.read_bytes(), "view.rbl": rbl.read_bytes()}, args.out, width, height, args.wait)


if __name__ == "__main__":
    main()
