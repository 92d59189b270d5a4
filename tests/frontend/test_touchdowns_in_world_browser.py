"""History's touchdowns view of a robot run in a stored world (frontend/panel/touchdowns.js), in
headless Chromium against the real service: the caption names the world (its name as text), the
legend and the RMS say "in world N", and the paper's model predicts the world climb's touchdowns."""

import re

import httpx
import pytest

from backend.store.database import make_engine, session_factory, sqlite_url
from sim_core.world.climb import climb_world
from sim_core.world.files import world_from_document
from tests.backend.services.test_run_prediction import GAIT, JUMPS, ROBOT, START, store_run, tracked
from tests.frontend.browser import chromium, panel, until
from tests.helpers import served

pytestmark = pytest.mark.slow  # a browser and a service (~10 s)

NAME = "<img src=x onerror=alert(1)> narrowing"  # a world's name stays text
TRACES = "document.querySelector('#touchdown-plot').data?.map((t) => t.name).join('|') ?? ''"


@pytest.fixture(scope="module")
def service(tmp_path_factory):
    data_dir = tmp_path_factory.mktemp("touchdowns-in-world") / "data"
    with served(data_dir, "--no-view") as (base, token):
        yield base, token, data_dir


@pytest.fixture(scope="module")
def run_in_world(service):
    """A robot run of sim_core's climb in a stored narrowing world: its id and the world's."""
    base, token, data_dir = service
    world = httpx.post(f"{base}/api/v1/worlds", json={"name": NAME, "named": "narrowing"},
                       headers={"Authorization": f"Bearer {token}"}, timeout=60).json()  # fmt: skip
    climb = climb_world(ROBOT.to_model(), world_from_document(world["world"], ROBOT.leg_length), GAIT, START, JUMPS)
    engine = make_engine(sqlite_url(data_dir))
    with session_factory(engine)() as session:
        run = store_run(session, tracked(climb), world["id"]).id
    engine.dispose()
    return run, world["id"]


def test_a_run_in_a_world_is_shown_against_the_models_jumps_in_that_world(service, run_in_world):
    base, token, _data_dir = service
    run, world_id = run_in_world
    with chromium() as browser, panel(browser, base, token) as page:
        page.click("nav [data-tab=history]")
        page.select_option("#history-form select[name=kind]", "robot")
        page.click("#history-form button[type=submit]")
        until(page, f"!!document.querySelector('#run-{run}')")
        page.click(f"#run-{run} button.show-touchdowns")
        until(page, f'{TRACES} === "measured|paper\'s model in world {world_id}"')
        title = page.inner_text("#touchdowns-title")
        assert f"each predicted by a jump in world {world_id} ({NAME}), not between parallel walls" in title, title
        rms = page.inner_text("#touchdowns-rms")
        found = re.search(rf"paper in world {world_id}: xdot (\S+) √\(g l0\), ydot (\S+) √\(g l0\), rise (\S+) l0", rms)
        assert found and max(abs(float(value)) for value in found.groups()) < 1e-9, rms
        plot_title = page.evaluate("document.querySelector('#touchdown-plot').layout.title.text")
        assert plot_title.endswith(f"measured and predicted in world {world_id}"), plot_title
        assert page.evaluate("document.querySelectorAll('#touchdowns-box img').length") == 0, "no markup from a name"
