"""An MFPT job in the Jobs tab (issue 28), in headless Chromium against the real service: listed by
what it asks, and shown as its estimate and each grid's MFPT drawn from the job's own result.

Set PARKOUR_SCREENSHOTS=1 to refresh docs/screenshots/mfpt_job.png from this run.
"""

import time

import httpx
import pytest

from tests.frontend.browser import chromium, panel, screenshot, until
from tests.helpers import served

pytestmark = pytest.mark.slow  # a browser, a service and a chain: ~20 s

NEWEST = "document.querySelector('#job-table tbody tr:first-child {cell}')?.textContent"
# Small and quick: no pitch drift (one layer), a coarse grid, the gait's state given.
SPEC = {"kind": "mfpt", "zeta0": 0.9, "start": {"xdot": -0.9339, "ydot": -0.1661}, "grid": 8, "pitch_spacing": 2.0,
        "noise": {"pitch_drift_deg": 0.0, "velocity": 0.1}}  # fmt: skip


@pytest.fixture(scope="module")
def service(tmp_path_factory):
    with served(tmp_path_factory.mktemp("mfpt") / "data") as base_and_token:
        yield base_and_token


def _done(base: str, job: int) -> dict:
    deadline = time.monotonic() + 240  # a first compile of the chain's kernels in the job worker
    while (state := httpx.get(f"{base}/api/v1/jobs/{job}").json())["state"] not in ("done", "failed", "cancelled"):
        assert time.monotonic() < deadline, state
        time.sleep(0.5)
    return state


def test_an_mfpt_job_is_listed_and_shown_as_its_estimate_and_grids(service):
    base, token = service
    job = httpx.post(f"{base}/api/v1/jobs", json=SPEC, headers={"Authorization": f"Bearer {token}"}).json()["id"]
    assert _done(base, job)["state"] == "done"
    result = httpx.get(f"{base}/api/v1/jobs/{job}/results").json()["result"]
    with chromium() as browser, panel(browser, base, token, failed_requests=True) as page:
        page.set_viewport_size({"width": 1360, "height": 1200})
        page.click("nav [data-tab=jobs]")
        until(page, f"{NEWEST.format(cell='.state')} === 'done'")
        assert page.evaluate(NEWEST.format(cell=".what")) == "MFPT of 30°/0.9, grid 8"
        page.click("#job-table tbody tr:first-child .show")
        until(page, "document.querySelector('#job-plot').data?.[0]?.y?.length === 2")
        drawn = page.evaluate("document.querySelector('#job-plot').data[0]")
        assert drawn["y"] == [grid["mfpt_jumps"] for grid in result["grids"]]
        assert drawn["x"] == [grid["cells"] for grid in result["grids"]]
        said = page.evaluate("document.querySelector('#messages').textContent")
        assert f"Job {job}: MFPT " in said and f"{result['cells']} cells" in said
        screenshot(page, "mfpt_job", "#jobs")
