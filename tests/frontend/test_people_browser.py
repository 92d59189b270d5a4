"""Named people in the panel (issue 40), in headless Chromium against the real service: two people
with tokens made while it runs (``parkour token add``'s file), each signed in as themselves; the
Jobs table says who submitted each job and through what, History who made each run, and the
e-stop banner who pressed it.

Set PARKOUR_SCREENSHOTS=1 to refresh docs/screenshots/who_started_what.png from this run.
"""

from __future__ import annotations

import httpx
import pytest

from backend.store.people import PeopleFile
from tests.frontend.browser import chromium, panel, screenshot, until
from tests.helpers import served

pytestmark = pytest.mark.slow  # a browser and a service: ~15 s

JOB = {"zeta0s": [0.9], "trials": 2, "cap": 20}
RUN = {"start": {"xdot": -0.93, "ydot": -0.17}, "controls": [{"psi0_deg": 30, "zeta0": 0.88}], "jumps": 4}


@pytest.fixture(scope="module")
def service(tmp_path_factory):
    data_dir = tmp_path_factory.mktemp("people") / "data"
    with served(data_dir) as (base, _lab):
        people = PeopleFile(data_dir)  # as parkour token add does, while the service runs
        yield base, people.add("ada"), people.add("bob")


def test_the_panel_says_who_started_what(service):
    base, ada, bob = service
    with httpx.Client(base_url=f"{base}/api/v1", timeout=60) as api:
        bobs = {"Authorization": f"Bearer {bob}", "X-Parkour-Client": "sweep-script"}
        assert api.post("/runs", json=RUN, headers=bobs).status_code == 201
        assert api.post("/jobs", json=JOB, headers=bobs).status_code == 202
        with chromium() as browser, panel(browser, base, ada, failed_requests=True) as page:
            assert page.inner_text("#token-status") == "signed in as ada"
            page.click("nav [data-tab=jobs]")
            page.fill("#job-form input[name=trials]", "2")
            page.click("#submit-job")
            newest = "document.querySelector('#job-table tbody tr:first-child td.by')?.textContent"
            until(page, f"{newest} === 'ada via panel'")
            older = "document.querySelector('#job-table tbody tr:nth-child(2) td.by')?.textContent"
            assert page.evaluate(older) == "bob via sweep-script", "the header labels the tool, not the person"
            screenshot(page, "who_started_what", "#jobs")
            page.click("nav [data-tab=history]")
            made_by = "document.querySelector('#run-table tbody tr .col-created .by')?.textContent"
            until(page, f"{made_by} === 'by bob'")
            assert api.post("/robot/estop").status_code == 200  # no token: someone at this address
            until(
                page, "document.querySelector('#estop-reason').textContent.includes('Pressed by someone at 127.0.0.1')"
            )
