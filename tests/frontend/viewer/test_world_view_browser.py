"""The 3D view following a plan in a random-foothold world, in headless Chromium (SwiftShader):
the canvas draws the world's slabs, and the picture is docs/screenshots/view_world_plan.png
(with PARKOUR_SCREENSHOTS set; /tmp otherwise)."""

import contextlib
import time

from tests.frontend.browser import VIEWPORT, chromium, screenshot
from tests.frontend.viewer.view_service import wait_for

GOAL = 1.2  # [m]


def test_the_view_follows_a_plan_in_a_random_world(service):
    client, auth, view = service
    world = client.post("/api/v1/worlds", json={"name": "random holds", "random": {"seed": 3}}, headers=auth).json()
    before = set(view.sessions)
    with chromium() as browser:
        page = browser.new_page(viewport=VIEWPORT)
        page.goto(f"http://127.0.0.1:{view.server.get_port()}/")
        wait_for(lambda: set(view.sessions) - before, timeout=60)
        (session,) = (view.sessions[key] for key in set(view.sessions) - before)
        follow = session.modes["simulate"].follow
        follow.refresh()
        follow.gui_world.value = f"{world['id']}: random holds"
        follow.gui_goal.value, follow.gui_seed.value = GOAL, 4
        follow.request()
        wait_for(lambda: follow.active or "Cannot" in follow.note, timeout=120)
        assert follow.active, follow.note
        end = float(follow.recording.touchdowns[-1, 0])
        wait_for(lambda: follow.time >= 0.8 * end, timeout=60)
        session.modes["simulate"].playing = False
        time.sleep(2.0)  # the browser draws the paused frame and the readout
        assert session.scene.targets.count >= 3
        page.get_by_text("footholds hit").wait_for(timeout=30_000)
        with contextlib.suppress(Exception):  # viser's note that WebGL runs in software: not the view's
            page.locator(".mantine-Notification-closeButton").first.click(timeout=2_000)
            time.sleep(0.5)
        screenshot(page, "view_world_plan")
