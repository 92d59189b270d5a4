"""The closed-loop benchmark in the Jobs tab (issue 27), in headless Chromium against the real
service: scheduled from the form, shown as a row per controller and three plots drawn from the
job's own result, and bad input marked at its field with the service's reason.

Set PARKOUR_SCREENSHOTS=1 to refresh docs/screenshots/control_study.png from this run.
"""

import math

import httpx
import pytest

from tests.frontend.browser import chromium, panel, screenshot, until
from tests.helpers import served

pytestmark = pytest.mark.slow  # a browser and a service: ~20 s

STUDY_ROWS = "document.querySelectorAll('#job-study tbody tr')"
NEWEST = "document.querySelector('#job-table tbody tr:first-child {cell}')?.textContent"


@pytest.fixture(scope="module")
def service(tmp_path_factory):
    with served(tmp_path_factory.mktemp("study") / "data") as base_and_token:
        yield base_and_token


@pytest.fixture(scope="module")
def page(service):
    base, token = service
    with chromium() as browser, panel(browser, base, token, failed_requests=True) as view:
        view.set_viewport_size({"width": 1360, "height": 1500})
        yield view


def test_a_control_study_is_scheduled_and_shown_as_its_table_and_plots(page, service):
    page.click("nav [data-tab=jobs]")
    page.select_option("#job-kind", "control-study")
    page.select_option("select[name=study_controllers]", ["pid", "lqr", "deadbeat"])
    page.fill("input[name=study_seeds]", "30")
    page.fill("input[name=study_jumps]", "150")
    page.click("#submit-job")
    done = f"{NEWEST.format(cell='td:nth-child(2)')} === 'control-study' && {NEWEST.format(cell='.state')} === 'done'"
    until(page, done, timeout=90_000)
    assert "pid, lqr, deadbeat to 0.55 m, 30 × 150 jumps" in page.evaluate(NEWEST.format(cell=".what"))
    page.click("#job-table tbody tr:first-child .show")
    until(page, f"{STUDY_ROWS}.length === 3 && !document.querySelector('#job-plot-climbs').hidden")

    base, _ = service
    job = page.evaluate("document.querySelector('#job-table tbody tr:first-child td').textContent")
    result = httpx.get(f"{base}/api/v1/jobs/{job}/results").json()["result"]
    cells = page.evaluate(f"[...{STUDY_ROWS}].map((row) => [...row.cells].map((cell) => cell.textContent))")
    for shown, entry in zip(cells, result["controllers"], strict=True):
        assert shown[0] == entry["name"] and shown[1] == f"{entry['failures']}/30"
        bound = "≥ " if entry["survived"] else ""
        assert shown[2] == f"{bound}{math.floor(entry['mean_jumps_to_failure'] + 0.5)}"  # JavaScript's Math.round
        assert shown[3] == f"{entry['height_rms_m'] * 100:.2f} cm"
    failures = page.evaluate("document.querySelector('#job-plot').data.map((trace) => trace.y.at(-1))")
    assert failures == [entry["failures"] for entry in result["controllers"]]
    climbs = page.evaluate("document.querySelector('#job-plot-climbs').data.map((trace) => trace.name)")
    assert climbs == ["pid"] * 3 + ["lqr"] * 3 + ["deadbeat"] * 3, "the first three trials of each"
    assert page.evaluate("document.querySelector('#job-plot-errors').data.length") == 3
    screenshot(page, "control_study", "#jobs")

    # Another job's results put the study away.
    page.select_option("#job-kind", "sweep")
    page.fill("input[name=steps]", "4")
    page.fill("input[name=basin_grid]", "0")
    page.click("#submit-job")
    sweep_done = f"{NEWEST.format(cell='td:nth-child(2)')} === 'sweep' && {NEWEST.format(cell='.state')} === 'done'"
    until(page, sweep_done, timeout=90_000)  # 30 s ran out on a machine loaded 4x: a hang guard
    page.click("#job-table tbody tr:first-child .show")
    until(page, "document.querySelector('#job-study').hidden && document.querySelector('#job-plot-climbs').hidden")


@pytest.mark.parametrize(
    ("field", "value", "says"),
    [
        ("study_target", "2.5", "at most 2 m"),
        ("study_target", "0", "must be more than 0 and at most 2 m"),
        ("study_seeds", "0", "at least 1"),
    ],
)
def test_a_study_out_of_range_is_marked_at_its_field_and_not_sent(page, field, value, says):
    page.click("nav [data-tab=jobs]")
    page.select_option("#job-kind", "control-study")
    before = page.evaluate("document.querySelectorAll('#job-table tbody tr').length")
    page.fill(f"input[name={field}]", value)
    page.click("#submit-job")
    until(page, f"document.querySelector('input[name={field}]').getAttribute('aria-invalid') === 'true'")
    assert says in page.evaluate(f"document.querySelector('#{field}-error').textContent")
    page.fill(f"input[name={field}]", {"study_target": "0.55", "study_seeds": "30"}[field])
    assert page.evaluate("document.querySelectorAll('#job-table tbody tr').length") == before


def test_no_controller_chosen_is_the_services_reason_at_the_field(page):
    page.click("nav [data-tab=jobs]")
    page.select_option("#job-kind", "control-study")
    page.select_option("select[name=study_controllers]", [])
    page.click("#submit-job")
    until(page, "document.querySelector('select[name=study_controllers]').getAttribute('aria-invalid') === 'true'")
    assert "at least 1" in page.evaluate("document.querySelector('#study_controllers-error').textContent")
