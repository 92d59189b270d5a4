"""The Jobs tab's form (frontend/panel/job_forms.js), in headless Chromium against the real service:
a job kind the page has no fieldset for (the gait atlas) is offered from the service's catalog, its
form built from its request's schema (defaults, ranges), checked at its fields before anything is
sent, and scheduled with the body the API takes."""

import httpx
import pytest

from backend.jobs import KINDS
from tests.frontend.browser import chromium, panel, until
from tests.helpers import served

pytestmark = pytest.mark.slow  # a browser and a service

NEWEST = "document.querySelector('#job-table tbody tr:first-child {cell}')?.textContent"


@pytest.fixture(scope="module")
def service(tmp_path_factory):
    with served(tmp_path_factory.mktemp("forms") / "data") as base_and_token:
        yield base_and_token


@pytest.fixture(scope="module")
def page(service):
    base, token = service
    with chromium() as browser, panel(browser, base, token) as view:
        yield view


def test_the_kind_chooser_is_the_registry_less_what_needs_legs(page):
    """A gait search's legs are left to the API; a world-mjtf job's legs come with its world (job_world.js)."""
    page.click("nav [data-tab=jobs]")
    until(page, "document.querySelectorAll('#job-kind option').length > 0")
    offered = page.evaluate("[...document.querySelectorAll('#job-kind option')].map((option) => option.value)")
    assert offered == [kind.name for kind in KINDS if kind.name != "gaits"]


def test_a_kind_without_a_fieldset_gets_one_from_its_schema_and_is_scheduled(page, service):
    base, _ = service
    page.click("nav [data-tab=jobs]")
    page.select_option("#job-kind", "atlas")
    fieldset = "fieldset[data-kind=atlas][data-generated]"
    page.wait_for_selector(f"{fieldset}:not([hidden])")
    assert page.input_value("input[name=atlas__rows]") == "13", "the request's default"
    page.fill("input[name=atlas__rows]", "1")  # the schema's minimum is 2: marked here, nothing sent
    page.click("#submit-job")
    until(page, "document.querySelector('input[name=atlas__rows]').getAttribute('aria-invalid') === 'true'")
    assert "at least 2" in page.inner_text(f"{fieldset} .field-error")
    for name, value in {
        "rows": "2",
        "columns": "3",
        "transient": "60",
        "zeta0_low": "0.88",
        "zeta0_high": "0.94",
    }.items():
        page.fill(f"input[name=atlas__{name}]", value)
    page.click("#submit-job")
    until(page, f"{NEWEST.format(cell='td:nth-child(2)')} === 'atlas' && {NEWEST.format(cell='.state')} === 'done'",
          timeout=90_000)  # fmt: skip
    job = page.evaluate("document.querySelector('#job-table tbody tr:first-child td').textContent")
    spec = httpx.get(f"{base}/api/v1/jobs/{job}").json()["spec"]
    assert (spec["rows"], spec["columns"], spec["transient"], spec["zeta0_low"]) == (2, 3, 60, 0.88)
    assert "rows 2, columns 3" in page.evaluate(NEWEST.format(cell=".what"))
    result = httpx.get(f"{base}/api/v1/jobs/{job}/results").json()["result"]
    assert len(result["count"]) == 2 and len(result["count"][0]) == 3
