"""The section's jobs in the Jobs tab (issue 28), in headless Chromium against the real service:
a viability job (frontend/panel/viability.js) scheduled from the form, shown as the kernel's
measure over the states and a clicked state's viable commands unpacked from the job's own bits;
an MFPT job scheduled from the form with its noise, listed by what it asks and shown as its
estimate and each grid's MFPT drawn from the job's own result; a controller's MFPT by splitting
(frontend/panel/loop_mfpt.js) from the form, its fields checked against the API's ranges, shown as
its estimate in words and each run's failure probability. One service for all.

Set PARKOUR_SCREENSHOTS=1 to refresh docs/screenshots/viability_job.png, mfpt_job.png and
loop_mfpt_job.png.
"""

import base64
import time

import httpx
import numpy as np
import pytest

from tests.frontend.browser import chromium, panel, said, screenshot, until
from tests.helpers import served

pytestmark = pytest.mark.slow  # a browser, a service, a small map and a small chain: ~40 s

NEWEST = "document.querySelector('#job-table tbody tr:first-child {cell}')?.textContent"


@pytest.fixture(scope="module")
def service(tmp_path_factory):
    with served(tmp_path_factory.mktemp("viability") / "data") as base_and_token:
        yield base_and_token


def _newest_job(base: str, token: str) -> dict:
    return httpx.get(f"{base}/api/v1/jobs?limit=1", headers={"Authorization": f"Bearer {token}"}).json()["items"][0]


def _done(base: str, job: int) -> dict:
    deadline = time.monotonic() + 240  # a first compile of the kernels in the job worker
    while (state := httpx.get(f"{base}/api/v1/jobs/{job}").json())["state"] not in ("done", "failed", "cancelled"):
        assert time.monotonic() < deadline, state
        time.sleep(0.5)
    return state


def _schedule(page, kind: str, values: dict) -> None:
    page.select_option("#job-kind", kind)
    for name, value in values.items():
        page.fill(f"#job-form [name={name}]", str(value))
    page.click("#submit-job")


def test_a_viability_job_from_the_form_shows_its_kernel_and_a_states_viable_commands(service):
    base, token = service
    with chromium() as browser, panel(browser, base, token, failed_requests=True) as page:
        page.set_viewport_size({"width": 1360, "height": 1500})
        page.click("nav [data-tab=jobs]")
        _schedule(page, "viability", {"viability_states": 12, "viability_actions": 4, "viability_zeta0_low": 0.8})
        said(page, "scheduled")
        job = _newest_job(base, token)
        assert job["spec"]["states"] == 12 and job["spec"]["zeta0_low"] == 0.8
        assert _done(base, job["id"])["state"] == "done"
        result = httpx.get(f"{base}/api/v1/jobs/{job['id']}/results").json()["result"]
        until(page, f"{NEWEST.format(cell='.state')} === 'done'")
        assert page.evaluate(NEWEST.format(cell=".what")) == "viability, 12² states × 4² actions"
        page.click("#job-table tbody tr:first-child .show")
        until(page, "document.querySelector('#job-plot').data?.length === 3")
        measure = page.evaluate("document.querySelector('#job-plot').data[2].z")
        kernel, expected = np.array(result["kernel"]), np.array(result["measure"])
        drawn = np.array([[np.nan if v is None else v for v in row] for row in measure]).T  # back to [xdot][ydot]
        assert np.array_equal(np.isnan(drawn), ~kernel)
        np.testing.assert_allclose(drawn[kernel], expected[kernel])
        # A state in the kernel, clicked: its viable commands are the job's bits for that state.
        i, j = (int(v) for v in np.argwhere(kernel & (expected < 1))[0])
        x, y = result["state_axes"]["xdot"][i], result["state_axes"]["ydot"][j]
        page.evaluate(f"document.querySelector('#job-plot').emit('plotly_click', {{points: [{{x: {x}, y: {y}}}]}})")
        until(page, "document.querySelector('#job-plot-actions').data?.length === 1")
        shown = np.array(page.evaluate("document.querySelector('#job-plot-actions').data[0].z")).T  # [psi0][zeta0]
        bits = np.unpackbits(np.frombuffer(base64.b64decode(result["viable_pairs"]), dtype=np.uint8))
        shape = result["viable_pairs_shape"]
        assert np.array_equal(shown, bits[: np.prod(shape)].reshape(shape)[i, j])
        title = page.evaluate("document.querySelector('#job-plot-actions').layout.title.text")
        assert f"{int(shown.sum())} of 16 commands viable" in title
        screenshot(page, "viability_job", "#jobs")


def test_an_mfpt_job_from_the_form_is_listed_and_shown_as_its_estimate_and_grids(service):
    base, token = service
    with chromium() as browser, panel(browser, base, token, failed_requests=True) as page:
        page.set_viewport_size({"width": 1360, "height": 1200})
        page.click("nav [data-tab=jobs]")
        # Small and quick: no pitch drift (one layer), a coarse grid.
        _schedule(page, "mfpt", {"mfpt_zeta0": 0.9, "mfpt_velocity": 0.1, "mfpt_grid": 8, "mfpt_pitch": 2})
        until(page, "document.querySelector('#messages').textContent.includes('MFPT of 30°/0.9,')")
        job = _newest_job(base, token)
        spec = job["spec"]
        assert spec["kind"] == "mfpt" and spec["grid"] == 8 and spec["pitch_spacing"] == 2
        assert spec["noise"]["velocity"] == 0.1 and spec["noise"]["pitch_drift_deg"] == 0
        assert _done(base, job["id"])["state"] == "done"
        result = httpx.get(f"{base}/api/v1/jobs/{job['id']}/results").json()["result"]
        until(page, f"{NEWEST.format(cell='.state')} === 'done'")
        assert page.evaluate(NEWEST.format(cell=".what")) == "MFPT of 30°/0.9, grid 8"
        page.click("#job-table tbody tr:first-child .show")
        until(page, "document.querySelector('#job-plot').data?.[0]?.y?.length === 2")
        drawn = page.evaluate("document.querySelector('#job-plot').data[0]")
        assert drawn["y"] == [grid["mfpt_jumps"] for grid in result["grids"]]
        assert drawn["x"] == [grid["cells"] for grid in result["grids"]]
        said = page.evaluate("document.querySelector('#messages').textContent")
        assert f"Job {job['id']}: MFPT " in said and f"{result['cells']} cells" in said
        assert page.evaluate("document.querySelector('#job-plot-actions').hidden"), "the viability view is put away"
        screenshot(page, "mfpt_job", "#jobs")


def test_a_controllers_mfpt_job_from_the_form_is_shown_in_words_and_each_runs_probability(service):
    base, token = service
    with chromium() as browser, panel(browser, base, token, failed_requests=True) as page:
        page.set_viewport_size({"width": 1360, "height": 1300})
        page.click("nav [data-tab=jobs]")
        page.select_option("#job-kind", "loop-mfpt")
        page.select_option("#job-form [name=loop_controller]", "lqr")
        # Checked against the API's range before anything is sent.
        _schedule(page, "loop-mfpt", {"loop_replicas": 1001})
        until(page, "document.querySelector('[name=loop_replicas]').getAttribute('aria-invalid') === 'true'")
        assert "at most 1000" in page.evaluate("document.querySelector('#loop_replicas-error').textContent")
        # Small and quick: a few runs of a few replicas, velocity noise only, no pitch drift.
        _schedule(page, "loop-mfpt", {"loop_replicas": 40, "loop_runs": 8, "loop_velocity": 0.05, "loop_seed": 2})
        until(page, "document.querySelector('#messages').textContent.includes('MFPT of lqr at 0.55 m, 8 runs × 40')")
        job = _newest_job(base, token)
        spec = job["spec"]
        assert spec["kind"] == "loop-mfpt" and spec["controller"] == "lqr" and spec["target_m"] == 0.55
        assert (spec["replicas"], spec["runs"], spec["seed"]) == (40, 8, 2)
        assert spec["noise"]["velocity"] == 0.05 and spec["noise"]["pitch_drift_deg"] == 0
        assert _done(base, job["id"])["state"] == "done"
        result = httpx.get(f"{base}/api/v1/jobs/{job['id']}/results").json()["result"]
        until(page, f"{NEWEST.format(cell='.state')} === 'done'")
        assert page.evaluate(NEWEST.format(cell=".progress")).endswith("8/8"), "progress: one a splitting run"
        page.click("#job-table tbody tr:first-child .show")
        until(page, "document.querySelector('#job-plot').data?.[0]?.y?.length === 8")
        drawn = page.evaluate("document.querySelector('#job-plot').data[0]")
        assert drawn["y"] == result["splitting"]["probabilities"] and drawn["x"] == list(range(1, 9))
        words = page.evaluate("document.querySelector('#job-summary').textContent")
        mfpt, low, high = (f"{round(value):,}" for value in (result["mfpt_jumps"], *result["ci95"]))
        assert f"Job {job['id']}: lqr holds 0.55 m for about {mfpt} jumps (95%: {low}–{high})" in words
        assert "by splitting; λ₂ " in words and f"{result['lambda2']:.6f}" in words
        screenshot(page, "loop_mfpt_job", "#jobs")
        if page.locator("#job-table tbody tr .show").count() > 1:  # another job's view puts the words away
            page.click("#job-table tbody tr:nth-child(2) .show")
            until(page, "document.querySelector('#job-summary').hidden")


def test_a_bad_field_is_marked_at_the_field_and_nothing_is_sent(service):
    base, token = service
    with chromium() as browser, panel(browser, base, token) as page:
        page.click("nav [data-tab=jobs]")
        before = httpx.get(f"{base}/api/v1/jobs", headers={"Authorization": f"Bearer {token}"}).json()["items"]
        _schedule(page, "viability", {"viability_states": 500})
        until(page, "document.querySelector('[name=viability_states]').getAttribute('aria-invalid') === 'true'")
        after = httpx.get(f"{base}/api/v1/jobs", headers={"Authorization": f"Bearer {token}"}).json()["items"]
        assert len(after) == len(before)
