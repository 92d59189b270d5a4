"""Updates per second of the 3D view, per browser, with 1, 2 and 4 browsers connected.

Starts a ClimbView on a free port. Each browser has its own view (simulate mode at real-time
playback, its own climb and GUI), so the view's loop draws a frame for each of them. For each
count in ``--clients`` this connects that many headless browsers (websocket clients that speak
to the view as viser's web client does: tests/frontend/viewer/headless.py) and reports, over
``--seconds``: frames the loop drew per second, and per browser the updates (websocket
messages) and kB that reached it, and the service process's CPU per second.

``--browser`` adds one real browser (headless Chromium, SwiftShader WebGL: no GPU needed) beside
the headless ones, and reports the frames per second it painted (``requestAnimationFrame``).

    PYTHONPATH=. .venv/bin/python scripts/bench_view.py [--clients 1 2 4] [--seconds 10] [--browser]
"""

from __future__ import annotations

import argparse
import contextlib
import shutil
import time

from backend.services.view import ViewContext
from frontend.viewer.app import ClimbView
from tests.frontend.viewer.headless import HeadlessViewer

WARM_UP_S = 3.0  # the first scene, and each new view's first gait search
PAINT_RATE_JS = """(seconds) => new Promise((done) => {
  let frames = 0; const start = performance.now();
  const tick = (now) => {
    frames++;
    if (now - start < seconds * 1000) requestAnimationFrame(tick);
    else done(frames / ((now - start) / 1000));
  };
  requestAnimationFrame(tick);
})"""


@contextlib.contextmanager
def _chromium_page(port: int):
    """One real browser on the view (its painted frame rate), or None when not asked for."""
    from playwright.sync_api import sync_playwright

    with sync_playwright() as playwright:
        software_webgl = ["--use-angle=swiftshader", "--enable-unsafe-swiftshader"]
        browser = playwright.chromium.launch(executable_path=shutil.which("chromium"), args=software_webgl)
        page = browser.new_page(viewport={"width": 1280, "height": 800})
        page.goto(f"http://127.0.0.1:{port}/")
        page.wait_for_selector("canvas")
        try:
            yield page
        finally:
            browser.close()


def measure(view: ClimbView, clients: int, seconds: float, browser: bool) -> dict:
    port = view.server.get_port()
    viewers = [HeadlessViewer(port, f"bench-{clients}-{i}") for i in range(clients)]
    painted = None
    try:
        with contextlib.ExitStack() as stack:
            page = stack.enter_context(_chromium_page(port)) if browser else None
            time.sleep(WARM_UP_S)
            frames, cpu, start = view.frames, time.process_time(), time.monotonic()
            if page is not None:
                painted = page.evaluate(PAINT_RATE_JS, seconds)
            else:
                time.sleep(seconds)
            end = time.monotonic()
            elapsed = end - start
            rates = [viewer.updates_per_s(start, end) for viewer in viewers]
            return {
                "clients": clients,
                "sessions": len(view.sessions),
                "drawn": (view.frames - frames) / elapsed,
                "per_client": rates,
                "kb_per_s": [viewer.bytes / 1000 / (end - start + WARM_UP_S) for viewer in viewers],
                "cpu": (time.process_time() - cpu) / elapsed,
                "painted": painted,
            }
    finally:
        for viewer in viewers:
            viewer.close()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--clients", type=int, nargs="+", default=[1, 2, 4])
    parser.add_argument("--seconds", type=float, default=10.0)
    parser.add_argument("--browser", action="store_true", help="add one headless Chromium and report its paint rate")
    args = parser.parse_args()
    view = ClimbView(ViewContext(sessions=None, robot_service=None), port=0)
    try:
        print("browsers | views | loop frames/s | updates/s per browser (min-max) | kB/s each | CPU [cores]")
        for clients in args.clients:
            result = measure(view, clients, args.seconds, args.browser)
            rates = result["per_client"]
            print(
                f"{clients:8d} | {result['sessions']:5d} | {result['drawn']:13.1f} | "
                f"{min(rates):14.1f} - {max(rates):5.1f}           | {sum(result['kb_per_s']) / clients:9.0f} | "
                f"{result['cpu']:.2f}"
            )
            if result["painted"] is not None:
                print(f"         Chromium beside them painted {result['painted']:.1f} frames/s (software WebGL)")
            deadline = time.monotonic() + 10
            while view.sessions and time.monotonic() < deadline:  # the next count starts from none
                time.sleep(0.05)
    finally:
        view.close()


if __name__ == "__main__":
    main()
