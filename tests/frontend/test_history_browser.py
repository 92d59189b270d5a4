"""History at any size (issue 26), in headless Chromium against the real service: 1,200 runs paged
through from the service with the total shown, a compare basket that outlives pages and filters,
how each run ended and was driven, the whole view in the address bar and restored from it, an
experiment's page with its outcomes and jobs, and runs grouped over seeds with 95% intervals.

Set PARKOUR_SCREENSHOTS=1 to refresh docs/screenshots/history_*.png from this run.
"""

import random

import httpx
import pytest

from backend.repositories.runs import add_run
from backend.store.database import make_engine, migrate, session_factory, sqlite_url
from backend.store.models import Experiment
from backend.store.run_record import RunRecord
from tests.frontend.browser import chromium, panel, screenshot, until
from tests.helpers import served

pytestmark = pytest.mark.slow  # a browser and a service: ~40 s


SIMS, ROBOT_RUNS, REPLAYS = 1000, 180, 20
RUNS = SIMS + ROBOT_RUNS + REPLAYS
ZETA0S = (0.86, 0.88, 0.9, 0.92, 0.94)  # the experiment's settings, three seeds each
ENDINGS = ["jumps done"] * 5 + ["e-stop", "robot disarmed (fell or timed out)", "link lost", "stopped",
                                "error: the link write timed out"]  # fmt: skip
CLOSED_LOOP = {"target_m": 0.55, "kp": 0.04, "ki": 0.0, "kd": 0.02, "zeta0_min": 0.8, "zeta0_max": 0.98}
RANGE = "document.querySelector('#runs-range').textContent"
ROWS = "document.querySelectorAll('#run-table tbody tr')"


def _record(rng: random.Random, kind: str, zeta0: float, **changes) -> RunRecord:
    """A run as a simulation, a live robot run or a replay stores one (no simulation needed)."""
    touchdowns = rng.randrange(2, 16)
    fields = dict(kind=kind, status="done", model={"alpha": 77.6, "d_hat": 2.42, "c_zeta": 0.31, "c_psi": 0.31},
                  controls=[[30.0, zeta0]] if kind == "sim" else [[35.0, zeta0], [35.0, zeta0]],
                  start_state=[-0.93, -0.17], jumps=15, jumps_completed=15, code_version="test",
                  climb=round(10 * (0.96 - zeta0) + rng.gauss(0, 0.05), 4), results={},
                  tags=(rng.choice(["wet-wall", "dry", "baseline"]),))  # fmt: skip
    if kind != "sim":
        fields |= dict(jumps_completed=touchdowns - 1, results={"touchdowns": [{}] * touchdowns})
    if kind == "robot":
        ending = rng.choice(ENDINGS)
        closed = rng.random() < 0.3
        touchdowns = 15 if ending == "jumps done" else touchdowns  # it ends when it has the jumps asked for
        fields |= dict(jumps_completed=touchdowns - 1, results={"touchdowns": [{}] * touchdowns})
        fields["results"] |= {"end_reason": ending, "closed_loop": CLOSED_LOOP if closed else None}
        fields["status"] = "done" if ending in ("jumps done", "stopped") else "failed"
    return RunRecord(**(fields | changes))


@pytest.fixture(scope="module")
def store(tmp_path_factory):
    """A data directory with 1,200 runs (stored through the repository, as the service stores
    them) and an experiment of 15 simulations (5 zeta0s x 3 seeds) and a robot run that was
    e-stopped; its id."""
    data = tmp_path_factory.mktemp("history") / "data"
    data.mkdir()
    engine = make_engine(sqlite_url(data))
    migrate(engine)
    rng = random.Random(26)
    with session_factory(engine)() as session:
        notes = "Seeds 1-3 per setting.\nThe robot run was e-stopped at the wall's top."
        experiment = Experiment(name="energy over seeds", description="zeta0 0.86-0.94, three seeds each", notes=notes)
        session.add(experiment)
        session.flush()
        for k in range(RUNS):
            kind = "sim" if k < SIMS else "robot" if k < SIMS + ROBOT_RUNS else "replay"
            add_run(session, _record(rng, kind, rng.choice((0.85, 0.87, 0.89, 0.91, 0.93))))
        for zeta0 in ZETA0S:
            for seed in (1, 2, 3):
                fell = zeta0 >= 0.92 and seed != 1  # less energy: some seeds slip before the 15th jump
                jumps = rng.randrange(8, 15) if fell else 15
                seeded = _record(rng, "sim", zeta0, tags=(f"seed-{seed}",), jumps_completed=jumps)
                add_run(session, seeded, experiment_id=experiment.id)
        estopped = {"end_reason": "e-stop", "closed_loop": CLOSED_LOOP, "touchdowns": [{}] * 15}
        estop = _record(rng, "robot", 0.9, status="failed", results=estopped, jumps_completed=14)
        add_run(session, estop, experiment_id=experiment.id)
        session.commit()
        experiment_id = experiment.id
    engine.dispose()
    return data, experiment_id


@pytest.fixture(scope="module")
def service(store):
    data, experiment_id = store
    with served(data, "--no-view") as (base, token):
        yield base, token, experiment_id


@pytest.fixture(scope="module")
def browser():
    with chromium() as launched:
        yield launched


@pytest.fixture(scope="module")
def page(browser, service):
    base, token, _ = service
    with panel(browser, base, token) as view:
        yield view


def _range_is(page, text: str) -> None:
    until(page, f"{RANGE} === {text!r}")


def _as_shown(value: float) -> str:
    """A number as the panel writes it: 4 significant digits, as JavaScript prints a number."""
    rounded = float(f"{value:.4g}")
    return str(int(rounded)) if rounded.is_integer() else repr(rounded)


def _basket(page) -> list[int]:
    return page.evaluate(
        "[...document.querySelectorAll('#basket-runs .basket-remove')].map((b) => Number(b.dataset.run))"
    )


def _cells(page, rows: str) -> list[list[str]]:
    """The text of each cell of the rows ``rows`` selects, row by row."""
    return page.evaluate(f"[...document.querySelectorAll({rows!r})].map((r) => [...r.cells].map((c) => c.textContent))")


def _shown_ids(page) -> list[int]:
    return page.evaluate(f"[...{ROWS}].map((row) => Number(row.id.slice(4)))")


def test_history_pages_through_every_run_with_a_basket_across_filters(page, service):
    """Every run, a page at a time with the total; ticked runs stay in the basket across pages and
    filter changes, stay ticked when their page comes back, and leave it by their ×."""
    base, _, _ = service
    total = RUNS + 16
    page.click("nav [data-tab=history]")
    _range_is(page, f"runs 1–50 of {total:,} (page 1 of 25)")
    assert page.evaluate(f"{ROWS}.length") == 50 and page.is_disabled("#runs-prev")
    newest = _shown_ids(page)
    assert newest == sorted(newest, reverse=True) and newest[0] == total
    page.check(f"#run-{newest[3]} input[type=checkbox]")
    page.click("#runs-next")
    _range_is(page, f"runs 51–100 of {total:,} (page 2 of 25)")
    second = _shown_ids(page)
    assert second[0] < newest[-1], "the next page goes on where the first ended"
    page.check(f"#run-{second[10]} input[type=checkbox]")
    page.click("#runs-last")
    _range_is(page, f"runs 1,201–{total:,} of {total:,} (page 25 of 25)")
    assert page.is_disabled("#runs-next") and _shown_ids(page)[-1] == 1
    # A filter: the basket keeps the runs ticked under the one before.
    page.select_option("#history-form select[name=kind]", "robot")
    until(page, f"{RANGE}.startsWith('runs 1–50 of 181 ')")
    robot = _shown_ids(page)
    page.check(f"#run-{robot[0]} input[type=checkbox]")
    assert _basket(page) == [newest[3], second[10], robot[0]]
    assert page.inner_text("#basket-count") == "3 runs"
    page.select_option("#history-form select[name=size]", "100")
    until(page, f"{RANGE} === 'runs 1–100 of 181 (page 1 of 2)'")
    page.select_option("#history-form select[name=kind]", "")
    _range_is(page, f"runs 1–100 of {total:,} (page 1 of 13)")
    assert page.is_checked(f"#run-{newest[3]} input[type=checkbox]"), "a run in the basket is ticked when shown"
    assert not page.is_checked(f"#run-{newest[4]} input[type=checkbox]")
    # Sorted by a column's header, through every page.
    page.click("#run-table th[data-sort=climb] button")
    until(page, "document.querySelector('#run-table th[data-sort=climb]').getAttribute('aria-sort') === 'descending'")
    climbs = page.evaluate(f"[...{ROWS}].map((row) => Number(row.querySelector('.col-climb').textContent))")
    assert climbs == sorted(climbs, reverse=True)
    page.click("#runs-next")
    until(page, f"{RANGE}.startsWith('runs 101–200 ')")
    assert page.evaluate(f"Number({ROWS}[0].querySelector('.col-climb').textContent)") <= climbs[-1]
    page.click(f"#basket-runs button[data-run='{second[10]}']")
    assert _basket(page) == [newest[3], robot[0]]
    assert "basket=" in page.url and f"{newest[3]}%2C{robot[0]}" in page.url
    page.select_option("#history-form select[name=sort]", "-id")
    page.select_option("#history-form select[name=size]", "50")
    _range_is(page, f"runs 1–50 of {total:,} (page 1 of 25)")
    page.click("#runs-next")  # the robot runs: how each ended
    _range_is(page, f"runs 51–100 of {total:,} (page 2 of 25)")
    page.evaluate("window.scrollTo(0, 0)")
    table_fits = (
        "(() => { const box = document.querySelector('#run-table').parentElement;"
        " return box.scrollWidth <= box.clientWidth; })()"
    )
    assert page.evaluate(table_fits), "every column, edit, 3D and share included, shows without scrolling sideways"
    screenshot(page, "history_paging")
    assert httpx.get(f"{base}/api/v1/runs", params={"limit": 1}).json()["total"] == total


def test_how_each_run_ended_and_was_driven_stands_out(page):
    """An e-stop, a fall, a lost link and an error are badges; the ending, loop and controller
    filter; a robot run's jumps count its touchdowns; search finds notes and tags."""
    page.click("nav [data-tab=history]")
    page.select_option("#history-form select[name=end_reason]", "e-stop")
    until(page, f"{RANGE}.startsWith('runs 1–') && [...{ROWS}].every((row) => row.querySelector('.badge-estop'))")
    estop = page.locator("#run-table tbody tr .badge-estop").first
    assert estop.inner_text() == "e-stop" and estop.get_attribute("title") == "e-stop"
    assert page.evaluate(f"[...{ROWS}].every((row) => row.querySelector('.col-status').textContent === 'failed')")
    red = page.evaluate(f"getComputedStyle({ROWS}[0].querySelector('.badge-estop')).backgroundColor")
    assert red == "rgb(214, 31, 31)", "an e-stop stands out"
    page.select_option("#history-form select[name=end_reason]", "error")
    until(page, f"[...{ROWS}].length > 0 && [...{ROWS}].every((row) => row.querySelector('.badge-error'))")
    page.select_option("#history-form select[name=end_reason]", "")
    page.select_option("#history-form select[name=loop]", "closed")
    page.select_option("#history-form select[name=controller]", "pid")
    closed = "row.querySelector('.col-loop').textContent === 'closed'"
    held = "row.querySelector('.col-target').textContent === '0.55'"
    until(page, f"[...{ROWS}].length > 0 && [...{ROWS}].every((row) => {closed} && {held})")
    jumps = page.evaluate(
        f"[...{ROWS}].map((row) => row.querySelector('.col-jumps')).map((c) => [c.textContent, c.title])"
    )
    assert all(text.endswith("/15") and "touchdowns recorded" in title for text, title in jumps), jumps[:3]
    for name in ("loop", "controller"):
        page.select_option(f"#history-form select[name={name}]", "")
    page.fill("#history-form input[name=q]", "SEED-2")
    page.click("#history-form button[type=submit]")
    until(page, f"{RANGE} === 'runs 1–5 of 5 (page 1 of 1)'")
    assert page.evaluate(f"[...{ROWS}].every((row) => row.querySelector('.tags').textContent === 'seed-2')")
    page.fill("#history-form input[name=q]", "")
    page.click("#history-form button[type=submit]")
    until(page, f"{RANGE}.startsWith('runs 1–50 of ')")


def test_the_view_is_in_the_address_bar_and_a_link_restores_it(page, browser):
    """Filters, search, sort, page, page size, hidden columns and the basket: in the address, and
    a new browser opened at it shows the same runs, basket and columns (and no token)."""
    page.click("nav [data-tab=history]")
    page.select_option("#history-form select[name=kind]", "sim")
    page.fill("#history-form input[name=tag]", "wet-wall")
    page.select_option("#history-form select[name=sort]", "-climb")
    page.click("#history-form button[type=submit]")
    until(page, f"{RANGE}.startsWith('runs 1–50 of ')")
    page.click("#runs-next")
    until(page, f"{RANGE}.startsWith('runs 51–100 of ')")
    page.click("#run-columns summary")
    page.uncheck("#run-column-choices input[name=notes]")
    page.uncheck("#run-column-choices input[name=controller]")
    shown = _shown_ids(page)
    wanted = _basket(page)
    assert page.get_attribute("#history-link", "href") == page.url
    link, range_text = page.url, page.inner_text("#runs-range")
    assert "token" not in link and "kind=sim" in link and "page=2" in link and "hide=controller%2Cnotes" in link
    with browser.new_context(viewport={"width": 1360, "height": 900}) as elsewhere:
        other = elsewhere.new_page()
        other.goto(link)
        until(other, f"{RANGE} === {range_text!r}")
        assert other.get_attribute("#tab-history", "aria-selected") == "true"
        assert _shown_ids(other) == shown
        assert other.input_value("#history-form input[name=tag]") == "wet-wall"
        assert other.input_value("#history-form select[name=sort]") == "-climb"
        until(other, f"document.querySelectorAll('#basket-runs li').length === {len(wanted)}")
        assert _basket(other) == wanted
        assert other.is_hidden("#run-table tbody tr:first-child .col-notes")
        assert other.is_visible("#run-table tbody tr:first-child .col-climb")
        assert not other.is_checked("#run-column-choices input[name=notes]")
    page.check("#run-column-choices input[name=notes]")
    page.check("#run-column-choices input[name=controller]")
    page.click("#run-columns summary")
    page.fill("#history-form input[name=tag]", "")
    page.select_option("#history-form select[name=kind]", "")
    page.select_option("#history-form select[name=sort]", "-id")
    until(page, f"{RANGE}.startsWith('runs 1–50 of ')")


def test_an_experiments_page_has_its_outcomes_endings_and_jobs(page, service):
    """An experiment's name opens its page: notes, its runs' outcomes (mean ± std, the mean's 95%
    interval, over all and by kind), how its robot run ended, its jobs with a Show that opens the
    job in the Jobs tab; its runs are the list, filtered to it."""
    base, token, experiment = service
    job = {"experiment_id": experiment, "psi0_deg": 30, "zeta0s": [0.88, 0.9], "trials": 2, "cap": 10}
    job_id = httpx.post(f"{base}/api/v1/jobs", json=job, headers={"Authorization": f"Bearer {token}"}).json()["id"]
    page.reload()
    page.click("nav [data-tab=history]")
    page.click("#experiments-box summary")
    page.click(f"#experiment-table button[data-experiment='{experiment}']")
    until(page, "!document.querySelector('#experiment-page').hidden")
    _range_is(page, "runs 1–16 of 16 (page 1 of 1)")
    assert page.inner_text("#experiment-title") == f"Experiment {experiment}: energy over seeds"
    assert "e-stopped at the wall's top" in page.inner_text("#experiment-notes")
    assert page.inner_text("#experiment-counts").startswith("16 runs: 15 done, 1 failed")
    assert page.inner_text("#experiment-counts .badge-estop") == "e-stop"
    outcomes = _cells(page, "#experiment-outcomes tbody tr")
    assert [row[:2] for row in outcomes] == [["all", "16"], ["robot", "1"], ["sim", "15"]], outcomes
    assert " ± " in outcomes[0][2] and " … " in outcomes[0][3] and outcomes[1][3] == "— (one run)"
    until(page, f"document.querySelector('#experiment-jobs tbody tr td')?.textContent === '{job_id}'")
    page.locator("#experiment-page").scroll_into_view_if_needed()
    screenshot(page, "history_experiment")
    page.click(f"#experiment-jobs button[data-job='{job_id}']")
    until(page, "document.querySelector('#tab-jobs').getAttribute('aria-selected') === 'true'")
    until(page, f"(document.querySelector('#job-plot').textContent || '').includes('Job {job_id}')", timeout=60_000)
    page.click("nav [data-tab=history]")
    page.click("#experiment-close")
    everything = f"{RANGE}.endsWith('of {RUNS + 16:,} (page 1 of 25)')"
    until(page, f"document.querySelector('#experiment-page').hidden && {everything}")
    page.click("#experiments-box summary")


def test_runs_grouped_over_seeds_give_each_settings_mean_and_interval(page, service):
    """Group the experiment's simulations by zeta0: three seeds each, climb and jumps as mean ±
    std with the mean's 95% interval, drawn with the intervals as error bars; in the address too."""
    base, _, experiment = service
    page.click("nav [data-tab=history]")
    page.select_option("#history-form select[name=experiment_id]", str(experiment))
    page.select_option("#history-form select[name=kind]", "sim")
    _range_is(page, "runs 1–15 of 15 (page 1 of 1)")
    page.click("#group-runs")
    page.select_option("#aggregate-by", "zeta0")
    page.click("#aggregate-go")
    until(page, "document.querySelectorAll('#aggregate-table tbody tr').length === 5")
    rows = _cells(page, "#aggregate-table tbody tr")
    assert [row[:2] for row in rows] == [[str(z), "3"] for z in ZETA0S], rows
    asked = {"by": "zeta0", "experiment_id": experiment, "kind": "sim"}
    api = httpx.get(f"{base}/api/v1/runs/aggregate", params=asked).json()
    low = api["groups"][0]["climb"]
    assert rows[0][3] == f"{_as_shown(low['ci95_low'])} … {_as_shown(low['ci95_high'])}"
    page.wait_for_selector("#aggregate-plot .scatterlayer .trace")
    bars = page.evaluate("document.querySelector('#aggregate-plot').data[0].error_y.array.length")
    assert bars == 5
    assert "by=zeta0" in page.url
    page.locator("#aggregate-box").scroll_into_view_if_needed()
    screenshot(page, "history_aggregate", "#aggregate-box")
    page.click("#aggregate-close")
    assert page.is_hidden("#aggregate-box") and "by=" not in page.url
    page.select_option("#history-form select[name=kind]", "")
    page.select_option("#history-form select[name=experiment_id]", "")
    until(page, f"{RANGE}.startsWith('runs 1–50 of ')")


def test_the_basket_plots_a_parameter_against_an_outcome_and_compares(page):
    page.click("nav [data-tab=history]")
    page.click("#basket-clear")
    page.select_option("#history-form select[name=kind]", "sim")
    until(page, f"{RANGE}.startsWith('runs 1–50 of {SIMS + 15:,} ')")
    for run_id in _shown_ids(page)[:6]:
        page.check(f"#run-{run_id} input[type=checkbox]")
    page.click("#basket-plot-box summary")
    until(page, "document.querySelector('#basket-plot').data?.[0]?.x.length === 6")
    page.select_option("#basket-y", "jumps_completed")
    until(page, "document.querySelector('#basket-plot').layout.yaxis.title.text === 'jumps completed'")
    page.click("#compare")
    page.wait_for_selector("#compare-table")
    assert page.evaluate("document.querySelectorAll('#compare-table tr:first-of-type th').length") == 7
    page.click("#basket-clear")
    assert _basket(page) == [] and page.is_hidden("#basket-plot-box")
    page.select_option("#history-form select[name=kind]", "")


def test_the_basket_exports_and_groups_its_own_runs_not_the_filters(page, service):
    """Issue 40: CSV export and Group followed the filter (400 rows for a 4-run basket)."""
    base = service[0]
    page.click("nav [data-tab=history]")
    page.click("#basket-clear")
    assert page.is_hidden("#basket-export") and page.is_hidden("#basket-group")
    until(page, f"{RANGE}.startsWith('runs 1–50 of {RUNS + 16:,} ')")
    chosen = _shown_ids(page)[:4]
    for run_id in chosen:
        page.check(f"#run-{run_id} input[type=checkbox]")
    link = page.get_attribute("#basket-export", "href")
    exported = httpx.get(f"{base}{link}").text.splitlines()
    assert len(exported) == 1 + 4 and sorted(int(row.split(",")[0]) for row in exported[1:]) == sorted(chosen)
    page.click("#basket-group")
    page.select_option("#aggregate-by", "kind")
    page.click("#aggregate-go")
    until(page, "document.querySelector('#aggregate-table caption').textContent.startsWith('4 runs grouped')")
    page.click("#aggregate-close")
    page.click("#basket-clear")
