"""Time ``GET /api/v1/runs/{id}/share.html``: a stored run's replay as one standalone HTML file.

Starts the service in-process (``create_app`` with the real viser view, as ``parkour serve``
does, on a fresh data directory), stores runs through the API and times, for each:

- ``cold``: the first share of that run (the view already running, the run never shared):
  reading it from the store, then making the file;
- ``warm``: the same share again (best and median of ``--repeat``): the view keeps the last
  files it made (``ClimbView.share_html``), so this is a lookup;
- ``http``: the route itself, once, through the ASGI client;
- ``load``: reading the run(s) from the store as the view replays them (best of ``--repeat``):
  a sim run stored without its path is simulated again here;
- ``build``: making the file from the loaded run(s), nothing kept (``share.share_html``: best
  and median of ``--repeat``), what cold costs beside ``load``.

Runs: a simulated run of ``--jumps`` jumps with its path stored (``trajectory_rate`` 60 per
sqrt(l0/g)), the same run stored without a path (the view simulates it again), that run with
the other as a ghost, and a robot run (tracker frames at 120 Hz, body only). The issue's target:
1 s. ``--profile`` prints cProfile's top functions for one share of the longest sim run.

    .venv/bin/python scripts/bench_share.py [--jumps 20] [--repeat 5] [--profile]
"""

from __future__ import annotations

import argparse
import cProfile
import io
import pstats
import statistics
import tempfile
import time
from pathlib import Path

import numpy as np
from fastapi.testclient import TestClient

from backend.api.app import create_app
from backend.settings import Settings
from backend.store.models import Run
from backend.store.trajectory_blob import pack_trajectory
from frontend.viewer.app import ClimbView
from frontend.viewer.recordings import load_recording
from frontend.viewer.share import share_html

TRACKER_RATE = 120.0  # [Hz] the lab's tracker
PANEL_RATE = 60  # samples per sqrt(l0/g): what the panel's "Save run" stores


def _store_robot_run(view: ClimbView, like_run_id: int) -> int:
    """A robot run whose tracker frames follow a stored sim run's body (120 Hz, with touchdowns)."""
    recording = load_recording(view.context.sessions, like_run_id)
    clip = recording.clip
    t = np.arange(0.0, clip.end, 1.0 / TRACKER_RATE)
    poses = [clip.pose_at(float(s)) for s in t]
    frames = {"time": 1000.0 + t, "x": np.array([p.x for p in poses]), "y": np.array([p.y for p in poses])}
    touchdowns = [
        {"time": 1000.0 + time, "wall": int(wall), "foot_height": height} for time, wall, height in recording.touchdowns
    ]
    with view.context.sessions() as session:
        run = Run(kind="robot", status="done", code_version="bench", model={}, controls=[[30, 0.87], [30, 0.9]],
                  start_state=[0, 0], jumps=len(touchdowns), alpha=1, psi0_deg=30, zeta0=0.87,
                  jumps_completed=len(touchdowns), climb=0, results={"touchdowns": touchdowns},
                  trajectory=pack_trajectory(frames))  # fmt: skip
        session.add(run)
        session.commit()
        return run.id


def _time(call) -> tuple[float, object]:
    began = time.perf_counter()
    result = call()
    return time.perf_counter() - began, result


def _bench_case(view: ClimbView, client: TestClient, name: str, run_id: int, overlay: int | None, repeat: int) -> None:
    try:
        cold, html = _time(lambda: view.share_html(run_id, overlay))
    except MemoryError:  # run it under `ulimit -v`: the machine's memory is not the limit
        print(f"{name:<44} out of memory", flush=True)
        return
    warm = [_time(lambda: view.share_html(run_id, overlay))[0] for _ in range(repeat)]
    query = "" if overlay is None else f"?overlay_run_id={overlay}"
    http, answer = _time(lambda: client.get(f"/api/v1/runs/{run_id}/share.html{query}"))
    assert answer.status_code == 200, answer.text
    sessions = view.context.sessions
    runs = [run_id] if overlay is None else [run_id, overlay]
    load, recordings = min(_time(lambda: [load_recording(sessions, i) for i in runs]) for _ in range(repeat))
    build = [_time(lambda: share_html(*recordings))[0] for _ in range(repeat)]
    print(
        f"{name:<44} {cold:6.2f}s {min(warm):6.2f}/{statistics.median(warm):5.2f}s {http:6.2f}s"
        f" {load:6.2f}s {min(build):6.2f}/{statistics.median(build):5.2f}s {len(html) / 1e6:7.2f}MB",
        flush=True,
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--jumps", type=int, nargs="+", default=[20, 1100])
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--profile", action="store_true", help="cProfile one share of the longest sim run")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as data:
        settings = Settings.from_environment(Path(data) / "data")
        app = create_app(settings, view_factory=lambda context: ClimbView(context, port=0))
        with TestClient(app, base_url="http://127.0.0.1") as client:  # a Host the service allows
            token = (settings.data_dir / "api_token").read_text().strip()
            auth = {"Authorization": f"Bearer {token}"}
            view = app.state.view_starter.wait(120)
            assert view is not None, app.state.view_starter.unavailable_reason
            print(f"share.html, warm = best/median of {args.repeat}")
            print(f"{'run':<44} {'cold':>7} {'warm':>15} {'http':>7} {'load':>7} {'build':>15} {'size':>9}")
            for jumps in args.jumps:
                body = {
                    "controls": [{"psi0_deg": 30, "zeta0": 0.87}, {"psi0_deg": 30, "zeta0": 0.9}],
                    "start": {"xdot": -0.8, "ydot": -0.15},
                    "jumps": jumps,
                }
                answer = client.post("/api/v1/runs", json=body | {"trajectory_rate": PANEL_RATE}, headers=auth)
                assert answer.status_code == 201, answer.text
                stored = answer.json()["id"]
                again = client.post("/api/v1/runs", json=body, headers=auth).json()["id"]
                robot = _store_robot_run(view, stored)
                duration = load_recording(view.context.sessions, stored).duration
                cases = [
                    (f"sim, {jumps} jumps ({duration:.0f} s), path stored", stored, None),
                    (f"sim, {jumps} jumps, simulated again", again, None),
                    (f"sim, {jumps} jumps, with a sim ghost", stored, again),
                    (f"robot, {jumps} jumps, tracker 120 Hz", robot, None),
                ]
                for name, run_id, overlay in cases:
                    _bench_case(view, client, name, run_id, overlay, args.repeat)
            if args.profile:
                profiler = cProfile.Profile()
                profiler.runcall(view.share_html, stored, None)  # the last, longest
                out = io.StringIO()
                pstats.Stats(profiler, stream=out).sort_stats("cumulative").print_stats(30)
                print(out.getvalue())


if __name__ == "__main__":
    main()
