"""Jobs in a stored world from the Jobs tab (issue 43), in headless Chromium against the real
service: a plan scheduled in a world chosen by name and drawn over that world (a numbered target
per touchdown, the steps' table as the API's result says), a foothold study on a chosen world or
on random ones, a world-mjtf job with its legs, a reach job drawn as a heatmap of its highest feet, a
goal above the world refused at its field, and a world's 422 said once in the banner (its location
not repeated).

Set PARKOUR_SCREENSHOTS=1 to refresh docs/screenshots/plan_over_world.png and jobs_in_world.png.
"""

import httpx
import pytest

from tests.frontend.browser import chromium, panel, said, screenshot, until
from tests.helpers import served

pytestmark = pytest.mark.slow  # a browser, a service and a plan search (~10 s)

NEWEST = "document.querySelector('#job-table tbody tr:first-child {cell}')?.textContent"
BANNER = "document.querySelector('#messages .message')?.textContent ?? ''"
CELLS = "[...document.querySelectorAll('{} tbody tr')].map((row) => [...row.cells].map((cell) => cell.textContent))"
TARGETS = "[...document.querySelectorAll('#job-plan-svg g.plan-target')]"
ENDING_WORDS = "async (codes) => codes.map((await import('/panel/reach_view.js')).endingWords)"
BAD_WORLD = (
    '{"units": "l0", "left": {"points": [[-1, 0], [-1, -5]], "mu": [null]}, '
    '"right": {"points": [[1, 0], [1, 9]], "mu": [null]}}'
)


@pytest.fixture(scope="module")
def service(tmp_path_factory):
    with served(tmp_path_factory.mktemp("jobs-in-world") / "data", "--no-view") as base_and_token:
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
    _api(service, "POST", "/worlds", json={"name": "walls", "named": "parallel"})
    return _api(service, "POST", "/worlds", json={"name": "stairs", "named": "staircase"})


@pytest.fixture(scope="module")
def page(service, stairs):
    base, token = service
    with chromium() as browser, panel(browser, base, token) as view:
        yield view


def _choose_kind(page, kind):
    page.click("nav [data-tab=jobs]")
    until(page, f"[...document.querySelectorAll('#job-kind option')].some((o) => o.value === {kind!r})")
    page.select_option("#job-kind", kind)
    page.wait_for_selector(f"fieldset[data-kind={kind}]:not([hidden])")


def _choose_world(page, kind, world):
    select = f"select[name={kind}__world_id]"
    until(page, f"[...document.querySelectorAll('{select} option')].some((o) => o.value === '{world['id']}')")
    page.select_option(select, str(world["id"]))
    assert page.evaluate(f"document.querySelector('{select}').selectedOptions[0].textContent") == (
        f"{world['name']} (#{world['id']})"
    ), "chosen by name"


def _schedule_and_wait(page, service, kind, timeout=180_000):
    """Schedule the form's job; its id once it is done (the table's newest row)."""
    page.click("#submit-job")
    said(page, "scheduled")
    until(page, f"{NEWEST.format(cell='td:nth-child(2)')} === {kind!r} && {NEWEST.format(cell='.state')} === 'done'",
          timeout=timeout)  # fmt: skip
    return int(page.evaluate(NEWEST.format(cell="td")))


def test_a_goal_above_the_world_is_refused_at_the_goal_field(page, stairs):
    _choose_kind(page, "plan")
    page.click("#submit-job")  # no world chosen: marked, nothing sent
    until(page, "document.querySelector('select[name=plan__world_id]').getAttribute('aria-invalid') === 'true'")
    assert page.inner_text("#plan__world_id-error") == "choose a stored world (the World tab makes one)"
    _choose_world(page, "plan", stairs)
    page.fill("input[name=plan__goal_height_m]", "90")  # within the schema's range, above the world
    page.click("#submit-job")
    until(page, "document.querySelector('input[name=plan__goal_height_m]').getAttribute('aria-invalid') === 'true'")
    message = page.inner_text("#plan__goal_height_m-error")
    assert message and not message.startswith("goal_height_m"), message
    assert page.query_selector("select[name=plan__world_id][aria-invalid=true]") is None


def test_a_plan_is_scheduled_in_a_chosen_world_and_drawn_over_it(page, service, stairs):
    _choose_kind(page, "plan")
    _choose_world(page, "plan", stairs)
    page.fill("input[name=plan__goal_height_m]", "0.5")
    page.fill("input[name=plan__seed]", "2")
    job = _schedule_and_wait(page, service, "plan")
    assert _api(service, "GET", f"/jobs/{job}")["world_id"] == stairs["id"]
    result = _api(service, "GET", f"/jobs/{job}/results")["result"]
    steps = result["plan"]
    assert result["reaches_goal"] and len(steps) >= 2
    assert page.evaluate(NEWEST.format(cell=".what")) == f"plan up world #{stairs['id']} to 0.5 m"
    page.click(f"#job-{job} button.show")
    until(page, "!document.querySelector('#job-plan').hidden && document.querySelector('.plan-goal') !== null")
    targets = page.evaluate(f"{TARGETS}.map((g) => [g.dataset.jump, g.dataset.side, g.textContent])")
    assert len(targets) == len(steps), "one target a touchdown"
    assert [(int(jump), side) for jump, side, _ in targets] == [(step["jump"], step["side"]) for step in steps]
    assert all(text.startswith(str(s["jump"])) for (_, _, text), s in zip(targets, steps, strict=True)), "numbered"
    assert page.locator("#job-plan-svg line.world-segment").count() > 10, "the staircase drawn under them"
    assert page.evaluate(CELLS.format("#job-plan-steps")) == [
        [str(s["jump"]), s["side"], str(s["segment"]), f"{s['target'][0]:.3f}", f"{s['target'][1]:.3f}",
         f"{s['psi0_deg']:.1f}", f"{s['zeta0']:.3f}"] for s in steps
    ]  # fmt: skip
    about = page.inner_text("#job-plan-about")
    assert f'"{stairs["name"]}" reaches the goal 0.5 m in {len(steps)} touchdown(s)' in about
    assert f"highest foot {result['highest_m']:.3f} m" in about
    assert f"chance to get through {result['chance']:.3f}" in about
    # The plan reaches the goal: its last target is at or above the goal's line (SVG's y grows downward).
    goal_y = page.evaluate("Number(document.querySelector('.plan-goal').getAttribute('y1'))")
    last_y = page.evaluate(f"Number({TARGETS}.at(-1).querySelector('circle').getAttribute('cy'))")
    assert last_y <= goal_y + 1
    page.locator("#job-plan").scroll_into_view_if_needed()
    page.evaluate("document.querySelector('#estop').hidden = true")  # fixed over the window's corner: not the section's
    try:
        screenshot(page, "plan_over_world", "#job-plan")
    finally:
        page.evaluate("document.querySelector('#estop').hidden = false")


def test_a_foothold_study_on_a_chosen_world(page, service, stairs):
    _choose_kind(page, "foothold-study")
    assert page.is_hidden("input[name=foothold-study__random_count]"), "a stored world first"
    _choose_world(page, "foothold-study", stairs)
    page.fill("input[name=foothold-study__goal_height_m]", "0.5")
    page.fill("input[name=foothold-study__trials]", "3")
    page.fill("input[name=foothold-study__cap]", "60")
    job = _schedule_and_wait(page, service, "foothold-study")
    spec = _api(service, "GET", f"/jobs/{job}")["spec"]
    assert (spec["world_id"], spec["random_worlds"], spec["trials"]) == (stairs["id"], None, 3)
    result = _api(service, "GET", f"/jobs/{job}/results")["result"]
    page.click(f"#job-{job} button.show")
    until(page, "!document.querySelector('#job-footholds').hidden")
    methods = page.evaluate(CELLS.format("#job-footholds-methods"))
    assert [row[1] for row in methods] == [
        f"{m['reached']}/{m['trials']} ({100 * m['reached'] / m['trials']:.0f}%)" for m in result["methods"].values()
    ]
    assert methods[0][0].startswith("open-loop") and methods[1][0].startswith("placement")
    for row, method in zip(methods, result["methods"].values(), strict=True):
        for code, count in method["failures_by_code"].items():
            assert f"{code.replace('_', ' ')} {count}" in row[2]
        assert row[3] == f"{method['mean_jumps']:.1f}"
    worlds = page.evaluate(CELLS.format("#job-footholds-worlds"))
    assert [row[0] for row in worlds] == [world["world"] for world in result["worlds"]] == ["stairs"]
    page.set_viewport_size({"width": 1360, "height": 1100})
    page.evaluate("window.scrollTo(0, 0)")
    screenshot(page, "jobs_in_world")
    page.set_viewport_size({"width": 1360, "height": 900})


def test_a_foothold_study_on_random_worlds_and_a_world_mjtf_with_legs(page, service, stairs):
    _choose_kind(page, "foothold-study")
    page.select_option("select[name=foothold-study__source]", "random")
    assert page.is_hidden("select[name=foothold-study__world_id]")
    assert page.is_visible("input[name=foothold-study__random_count]")
    page.fill("input[name=foothold-study__random_count]", "1")
    page.fill("input[name=foothold-study__random_seed0]", "4")
    page.fill("input[name=foothold-study__goal_height_m]", "0.3")
    page.fill("input[name=foothold-study__trials]", "1")
    page.fill("input[name=foothold-study__cap]", "20")
    with page.expect_request(lambda request: request.url.endswith("/api/v1/jobs") and request.method == "POST") as sent:
        page.click("#submit-job")
    body = sent.value.post_data_json
    assert body["random_worlds"] == {"count": 1, "seed0": 4} and "world_id" not in body
    said(page, "scheduled")

    _choose_kind(page, "world-mjtf")
    _choose_world(page, "world-mjtf", stairs)
    page.fill("input[name=world-mjtf__psi0s]", "30, 28")
    page.fill("input[name=world-mjtf__zeta0s]", "0.9")
    page.click("#submit-job")  # two psi0, one zeta0: marked, nothing sent
    until(page, "document.querySelector('input[name=world-mjtf__zeta0s]').getAttribute('aria-invalid') === 'true'")
    page.fill("input[name=world-mjtf__zeta0s]", "0.9, 0.88")
    page.fill("input[name=world-mjtf__trials]", "4")
    page.fill("input[name=world-mjtf__cap]", "50")
    job = _schedule_and_wait(page, service, "world-mjtf")
    spec = _api(service, "GET", f"/jobs/{job}")["spec"]
    assert spec["world_id"] == stairs["id"] and spec["trials"] == 4
    assert [(leg["psi0_deg"], leg["zeta0"]) for leg in spec["controls"]] == [(30, 0.9), (28, 0.88)]
    page.click(f"#job-{job} button.show")
    until(page, "document.querySelector('#job-summary').textContent.includes('climb(s) in \"stairs\"')")


def test_a_reach_job_on_a_chosen_world_is_drawn_as_a_heatmap_of_its_highest_feet(page, service, stairs):
    _choose_kind(page, "reach")
    _choose_world(page, "reach", stairs)
    assert page.input_value("input[name=reach__psi0_range]") == "20, 40", "the request's default range"
    page.fill("input[name=reach__psi0_range]", "35, 25")  # each in range, reversed: the API's 422, at its field
    for name, value in {"psi0_steps": "3", "zeta0_steps": "2", "jumps": "10"}.items():
        page.fill(f"input[name=reach__{name}]", value)
    page.click("#submit-job")
    until(page, "document.querySelector('input[name=reach__psi0_range]').getAttribute('aria-invalid') === 'true'")
    assert "low below high" in page.inner_text("#reach__psi0_range-error")
    page.fill("input[name=reach__psi0_range]", "25, 35")
    job = _schedule_and_wait(page, service, "reach")
    spec = _api(service, "GET", f"/jobs/{job}")["spec"]
    assert (spec["world_id"], spec["psi0_range"], spec["psi0_steps"], spec["jumps"]) == (stairs["id"], [25, 35], 3, 10)
    result = _api(service, "GET", f"/jobs/{job}/results")["result"]
    page.click(f"#job-{job} button.show")
    until(page, "document.getElementById('job-plot').data?.[0]?.type === 'heatmap'")
    drawn = page.evaluate("(({x, y, z, text}) => ({x, y, z, text}))(document.getElementById('job-plot').data[0])")
    assert drawn["x"] == result["psi0_deg"] == [25, 30, 35] and drawn["y"] == result["zeta0"]
    assert drawn["z"] == [[h * result["l0_m"] for h in row] for row in result["highest"]], "in metres"
    codes = sorted({code for row in result["ending"] for code in row} | set(result["outcomes"]))
    said_as = dict(zip(codes, page.evaluate(ENDING_WORDS, codes), strict=True))
    assert said_as["top"] == "reached the top" and said_as["floor"] == "fell to the floor"
    hover = [[f"{said_as[code]} after {jumps} jump(s)" for code, jumps in zip(endings, done, strict=True)]
             for endings, done in zip(result["ending"], result["completed"], strict=True)]  # fmt: skip
    assert drawn["text"] == hover, "each cell's ending"
    summary = page.inner_text("#job-summary")
    assert f'6 schedule(s) (3 psi0 × 2 zeta0) in "{stairs["name"]}", up to 10 jumps each' in summary
    assert all(f"{count} {said_as[code]}" in summary for code, count in result["outcomes"].items() if count)


def test_a_worlds_refusal_names_its_location_once(page):
    """The banner said "Create world: world.left.points[1]: world.left.points[1]: y must …": the
    service's message names the location already."""
    page.click("nav [data-tab=world]")
    page.select_option("#world-source", "json")
    page.fill("#world-create-form textarea[name=json]", BAD_WORLD)
    page.fill("#world-create-form input[name=name]", "bad")
    page.click("#world-create")
    until(page, f"{BANNER}.startsWith('Create world: ')")
    message = page.inner_text(".message.error")
    expected = "Create world: world.left.points[1]: y must increase strictly bottom to top: -5.0 after 0.0"
    assert message == expected, message


def test_a_plans_monte_carlo_climbs_are_said(page):
    """With ``attempts``, the result's "monte_carlo": its failures of its trials and their interval."""
    job = {"spec": {"goal_height_m": 0.5}}
    result = {"reaches_goal": True, "plan": [{}, {}], "chance": 0.9, "highest_m": 0.61, "seconds": 2.0,
              "monte_carlo": {"trials": 40, "failures": 3, "failure_chance_ci95": [0.016, 0.204],
                              "mean_attempt_jumps": 4.5, "mfpt_jumps": 60.0}}  # fmt: skip
    words_of = "async ([job, result]) => (await import('/panel/plan_view.js')).planWords(7, job, result, 'stairs')"
    words = page.evaluate(words_of, [job, result])
    assert "reaches the goal 0.5 m in 2 touchdown(s)" in words
    assert "40 noisy climbs by the placement law: 3 failed (7.5%, 95%: 1.6%–20.4%)" in words
    assert "about 60 jumps to a failure" in words


def test_a_plans_importance_sampled_climbs_are_said(page):
    """With ``importance_sampling``: the climbs, what was widened, the chance, its interval, the ESS and any warning."""
    job = {"spec": {"goal_height_m": 0.5}}
    sampled = {"trials": 10000, "scale": 3.0, "scaled": ["psi0", "zeta0"], "first_leg_only": True,
               "failure_chance": 4.4e-5, "failure_chance_ci95": [3.4e-5, 5.3e-5], "effective_sample_size": 812.4,
               "warning": "<b>few</b> effective failures"}  # fmt: skip
    result = {
        "reaches_goal": True,
        "plan": [{}],
        "chance": 0.99,
        "highest_m": 0.6,
        "seconds": 1.0,
        "importance_sampling": sampled,
    }
    words_of = "async ([job, result]) => (await import('/panel/plan_view.js')).planWords(7, job, result, 'stairs')"
    words = page.evaluate(words_of, [job, result])
    assert "10000 importance-sampled climbs (psi0, zeta0 draws × 3 at touchdown 0)" in words, words
    assert "failure chance 0.000044 (95%: 0.000034–0.000053), effective sample size 812" in words, words
    assert words.endswith("— <b>few</b> effective failures."), "the service's words, as text"
