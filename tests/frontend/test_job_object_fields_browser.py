"""The object fields of the Jobs tab's generated forms (frontend/panel/job_object_fields.js), in
headless Chromium against the real service: a plan's ``importance_sampling`` and a reach's
``state`` are fieldsets of their properties behind a "set <name>" checkbox — checked, the body
sends the nested object and the job's spec keeps it; unchecked, the field is left out (the
service's default) — a nested value out of the schema's range is marked at its input and nothing is
sent, and the service's 422 at a nested property is put at that property's input.

Set PARKOUR_SCREENSHOTS=1 to refresh docs/screenshots/plan_importance_sampling_form.png.
"""

import json

import httpx
import pytest

from tests.frontend.browser import chromium, panel, said, screenshot, until
from tests.helpers import served

pytestmark = pytest.mark.slow  # a browser and a service

POSTED_JOB = "/api/v1/jobs"
IS = "plan__importance_sampling"  # the plan form's importance_sampling inputs: IS__trials, IS__scale …


@pytest.fixture(scope="module")
def service(tmp_path_factory):
    with served(tmp_path_factory.mktemp("object-fields") / "data", "--no-view") as base_and_token:
        yield base_and_token


def _api(service, method, path, **kwargs):
    base, token = service
    response = httpx.request(method, f"{base}/api/v1{path}", headers={"Authorization": f"Bearer {token}"},
                             timeout=60, **kwargs)  # fmt: skip
    response.raise_for_status()
    return response.json() if response.content else None


@pytest.fixture(scope="module")
def stairs(service):
    """A stored world, before the page loads (its choosers list it)."""
    return _api(service, "POST", "/worlds", json={"name": "stairs", "named": "staircase"})


@pytest.fixture(scope="module")
def page(service, stairs):
    base, token = service
    with chromium() as browser, panel(browser, base, token) as view:
        yield view


def _plan_form(page, world, *, sampled: bool):
    """The plan form with a world and a goal, its importance_sampling set (or not)."""
    page.click("nav [data-tab=jobs]")
    until(page, "[...document.querySelectorAll('#job-kind option')].some((o) => o.value === 'plan')")
    page.select_option("#job-kind", "plan")
    page.wait_for_selector("fieldset[data-kind=plan]:not([hidden])")
    select = "select[name=plan__world_id]"
    until(page, f"[...document.querySelectorAll('{select} option')].some((o) => o.value === '{world['id']}')")
    page.select_option(select, str(world["id"]))
    page.fill("input[name=plan__goal_height_m]", "0.5")
    page.set_checked(f"input[name={IS}]", sampled)


def _submitted(page):
    """Click Schedule; the POSTed body and the job's id."""
    with page.expect_request(lambda request: request.method == "POST" and request.url.endswith(POSTED_JOB)) as sent:
        page.click("#submit-job")
    said(page, "scheduled")
    return sent.value.post_data_json, sent.value.response().json()["id"]


def _cancel(service, job):
    _api(service, "POST", f"/jobs/{job}/cancel")


def _marked(page, name):
    return f"document.querySelector('[name={name}]').getAttribute('aria-invalid') === 'true'"


def test_importance_sampling_set_is_sent_as_its_object_and_kept_in_the_spec(page, service, stairs):
    _plan_form(page, stairs, sampled=False)
    assert page.is_disabled(f"input[name={IS}__trials]"), "unset: its fieldset is off"
    assert page.input_value(f"input[name={IS}__scale]") == "1.5", "the schema's default"
    assert page.evaluate(f"[...document.querySelector('select[name={IS}__draws]').selectedOptions].length") == 4
    page.set_checked(f"input[name={IS}]", True)
    assert page.is_enabled(f"input[name={IS}__trials]")
    page.fill(f"input[name={IS}__trials]", "200")
    page.fill(f"input[name={IS}__scale]", "2")
    page.select_option(f"select[name={IS}__draws]", ["psi0"])
    page.set_checked(f"input[name={IS}__first_leg]", True)
    page.locator("fieldset[data-kind=plan]").scroll_into_view_if_needed()
    screenshot(page, "plan_importance_sampling_form", "fieldset[data-kind=plan]")
    body, job = _submitted(page)
    try:
        expected = {"trials": 200, "scale": 2, "draws": ["psi0"], "first_leg": True}
        assert body["importance_sampling"] == expected
        assert "noise" not in body and "state" not in body, "the other objects unset: the service's defaults"
        assert _api(service, "GET", f"/jobs/{job}")["spec"]["importance_sampling"] == expected
    finally:
        _cancel(service, job)


def test_importance_sampling_unset_is_left_out_of_the_body(page, service, stairs):
    _plan_form(page, stairs, sampled=False)
    body, job = _submitted(page)
    try:
        assert "importance_sampling" not in body
        assert _api(service, "GET", f"/jobs/{job}")["spec"]["importance_sampling"] is None
    finally:
        _cancel(service, job)


def test_a_plans_launch_gait_is_a_checkbox_sent_as_it_stands(page, service, stairs):
    """A yes/no of the request's own (a plan for the robot: from the velocity a robot launched on its
    first leg has) is a checkbox, its default the schema's; sent as true or false."""
    _plan_form(page, stairs, sampled=False)
    box = "input[name=plan__launch_gait]"
    assert not page.is_checked(box) and "robot" in (page.get_attribute(f"label:has({box})", "title") or "")
    for chosen in (True, False):
        page.set_checked(box, chosen)
        body, job = _submitted(page)
        try:
            stored = _api(service, "GET", f"/jobs/{job}")["spec"]
            assert body["launch_gait"] is chosen and stored["launch_gait"] is chosen
        finally:
            _cancel(service, job)


def test_a_reach_jobs_state_is_sent_as_xdot_and_ydot(page, service, stairs):
    page.click("nav [data-tab=jobs]")
    page.select_option("#job-kind", "reach")
    page.wait_for_selector("fieldset[data-kind=reach]:not([hidden])")
    select = "select[name=reach__world_id]"
    until(page, f"[...document.querySelectorAll('{select} option')].some((o) => o.value === '{stairs['id']}')")
    page.select_option(select, str(stairs["id"]))
    for name, value in {"psi0_steps": "2", "zeta0_steps": "2", "jumps": "5"}.items():
        page.fill(f"input[name=reach__{name}]", value)
    assert "< 0" in page.get_attribute("label:has(> input[name=reach__state__xdot])", "title")
    page.set_checked("input[name=reach__state]", True)
    page.fill("input[name=reach__state__xdot]", "-1.1")
    page.fill("input[name=reach__state__ydot]", "0.4")
    body, job = _submitted(page)
    try:
        assert body["state"] == {"xdot": -1.1, "ydot": 0.4}
        assert _api(service, "GET", f"/jobs/{job}")["spec"]["state"] == {"xdot": -1.1, "ydot": 0.4}
    finally:
        _cancel(service, job)


def test_a_nested_value_out_of_range_is_marked_at_its_input_and_nothing_is_sent(page, stairs):
    _plan_form(page, stairs, sampled=True)
    assert page.get_attribute(f"label:has(> input[name={IS}__scale])", "title") == "the draws' widening; in [1, 5]"
    page.fill(f"input[name={IS}__trials]", "200")
    page.fill(f"input[name={IS}__scale]", "9")
    page.select_option(f"select[name={IS}__draws]", [])  # none: the API takes 1 to 4
    posted = []
    listener = lambda request: request.method == "POST" and request.url.endswith(POSTED_JOB) and posted.append(1)  # noqa: E731
    page.on("request", listener)
    try:
        page.click("#submit-job")
        until(page, _marked(page, f"{IS}__scale"))
        assert page.inner_text(f"#{IS}__scale-error") == "must be at least 1 and at most 5"
        assert page.inner_text(f"#{IS}__draws-error") == "choose at least 1", "marked in the same pass"
        assert page.evaluate("document.activeElement.name") == f"{IS}__scale"
        said(page, "nothing was sent")
        page.wait_for_timeout(300)
        assert posted == [], "nothing sent"
    finally:
        page.remove_listener("request", listener)


def test_the_services_422_at_a_nested_property_is_put_at_its_input(page, stairs):
    """The form lets no trials below 2 through: the request is changed on its way (trials 1) so that
    the service itself answers 422 at ["body", "plan", "importance_sampling", "trials"]."""
    _plan_form(page, stairs, sampled=True)
    page.fill(f"input[name={IS}__trials]", "200")
    page.fill(f"input[name={IS}__scale]", "3")
    page.select_option(f"select[name={IS}__draws]", ["psi0", "zeta0"])

    def one_trial(route):
        if route.request.method != "POST":
            return route.continue_()
        body = route.request.post_data_json
        body["importance_sampling"]["trials"] = 1
        return route.continue_(post_data=json.dumps(body))

    page.route(f"**{POSTED_JOB}", one_trial)
    try:
        with page.expect_response(lambda response: response.url.endswith(POSTED_JOB) and response.status == 422):
            page.click("#submit-job")
        until(page, _marked(page, f"{IS}__trials"))
        assert "greater than or equal to 2" in page.inner_text(f"#{IS}__trials-error")
        assert page.query_selector("fieldset[data-kind=plan] [aria-invalid=true]:not([name$=__trials])") is None
        said(page, "Fix the marked field(s): the service refused them.")
    finally:
        page.unroute(f"**{POSTED_JOB}", one_trial)
