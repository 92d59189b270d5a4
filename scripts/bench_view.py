"""Frame rate of the 3D view at real-time playback (simulate mode), as a browser receives it.

Starts a ClimbView on a free port, opens it in headless Chromium (SwiftShader WebGL: no GPU
needed) and reports, over ``--seconds``: frames the view's loop drew per second, WebSocket
messages per second that reached the browser, and the frames per second the browser painted
(``requestAnimationFrame``; software WebGL paints far slower than a GPU would).

    .venv/bin/python scripts/bench_view.py [--seconds 10] [--width 1280 --height 800]
"""

from __future__ import annotations

import argparse
import shutil
import time

from playwright.sync_api import sync_playwright

from backend.services.view import ViewContext
from frontend.viewer.app import ClimbView

PAINT_RATE_JS = """(seconds) => new Promise((done) => {
  let frames = 0; const start = performance.now();
  const tick = (now) => {
    frames++;
    if (now - start < seconds * 1000) requestAnimationFrame(tick);
    else done(frames / ((now - start) / 1000));
  };
  requestAnimationFrame(tick);
})"""


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=10.0)
    parser.add_argument("--width", type=int, default=1280)
    parser.add_argument("--height", type=int, default=800)
    args = parser.parse_args()
    view = ClimbView(ViewContext(sessions=None, robot_service=None), port=0)
    try:
        with sync_playwright() as playwright:
            software_webgl = ["--use-angle=swiftshader", "--enable-unsafe-swiftshader"]
            browser = playwright.chromium.launch(executable_path=shutil.which("chromium"), args=software_webgl)
            page = browser.new_page(viewport={"width": args.width, "height": args.height})
            received: list[float] = []
            page.on("websocket", lambda ws: ws.on("framereceived", lambda _f: received.append(time.monotonic())))
            page.goto(f"http://127.0.0.1:{view.server.get_port()}/")
            page.wait_for_selector("canvas")
            time.sleep(3.0)  # the first scene and shader compilation
            frames_before, start = view.frames, time.monotonic()
            painted = page.evaluate(PAINT_RATE_JS, args.seconds)
            elapsed = time.monotonic() - start
            drawn = (view.frames - frames_before) / elapsed
            messages = sum(1 for t in received if t >= start) / elapsed
            browser.close()
    finally:
        view.close()
    print(f"view loop:  {drawn:6.1f} frames/s drawn and sent")
    print(f"browser:    {messages:6.1f} WebSocket messages/s received")
    print(f"browser:    {painted:6.1f} frames/s painted ({args.width}x{args.height}, software WebGL)")


if __name__ == "__main__":
    main()
