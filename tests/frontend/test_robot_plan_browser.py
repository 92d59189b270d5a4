"""The Robot tab's run that follows a plan in a world (frontend/panel/robot_plan.js), in headless
Chromium against the running service and the virtual robot climbing a random-foothold world: the
operator chooses a finished plan job, its plan is drawn over its world, the run starts from the
plan's legs, and its journal (each command with its target foothold) is shown as the run sends it
and as it is stored; the feet are marked where they met the world.

Set PARKOUR_SCREENSHOTS=1 to refresh docs/screenshots/robot_plan_run.png from this run.
"""

import json
import socket
import time

import httpx
import pytest

from tests.frontend.browser import chromium, panel, said, screenshot, until
from tests.helpers import free_port, served, start_robot_sim, stop_processes

# A browser, a service, and a plan followed in real time (the law answers within each stance):
# ./test.sh runs it with the realtime part, alone on the machine.
pytestmark = [pytest.mark.slow, pytest.mark.realtime]

ROBOT_STATE = "document.querySelector('#robot-state').textContent"
PLAN_WITHIN_S = 120.0  # a hang guard for the plan job (kernels compiled in the job worker)
# What the journal showed, each time it changed: (rows, caption).
JOURNAL_SEEN = """window.__journal = [];
new MutationObserver(() => window.__journal.push([
  document.querySelectorAll('#robot-journal tbody td:nth-child(2)').length,
  document.querySelector('#robot-journal-caption').textContent]))
  .observe(document.querySelector('#robot-journal'), {subtree: true, childList: true, characterData: true});"""
RUN_WITHIN_MS = 60_000  # a hang guard for a short climb in real time, not a timing assertion


@pytest.fixture(scope="module")
def service(tmp_path_factory):
    with served(tmp_path_factory.mktemp("robot-plan") / "data", "--view-port", "0") as base_and_token:
        yield base_and_token


def _plan_job(base: str, auth: dict, body: dict) -> int:
    job = httpx.post(f"{base}/api/v1/jobs", json=body, headers=auth).raise_for_status().json()["id"]
    deadline = time.monotonic() + PLAN_WITHIN_S
    while (state := httpx.get(f"{base}/api/v1/jobs/{job}").json()["state"]) not in ("done", "failed", "cancelled"):
        assert time.monotonic() < deadline, f"plan job {job} still {state}"
        time.sleep(0.2)
    assert state == "done"
    return job


def test_a_live_run_follows_a_chosen_plan_and_shows_its_journal(service, tmp_path):
    base, token = service
    auth = {"Authorization": f"Bearer {token}"}
    world = httpx.post(f"{base}/api/v1/worlds", json={"name": "holds 5", "random": {"seed": 5}}, headers=auth)
    world_id = world.raise_for_status().json()["id"]
    plan = {"kind": "plan", "world_id": world_id, "goal_height_m": 1.0, "launch_gait": True}
    job = _plan_job(base, auth, plan)
    near_top = _plan_job(base, auth, plan | {"goal_height_m": 1.95, "launch_gait": False})
    steps = httpx.get(f"{base}/api/v1/jobs/{job}/results").json()["result"]["plan"]

    # The virtual robot in a process of its own, as the robot is: its camera must not wait on this
    # process's browser driving (a CI run: "tracker silent: no frame for 111 ms" with it in here).
    robot_port, tracker_port = free_port(), free_port(socket.SOCK_DGRAM)
    world_file = tmp_path / "holds5.json"
    world_file.write_text(json.dumps(world.json()["world"]))
    robot = start_robot_sim(robot_port, tracker_port, "--world", str(world_file), "--noise", "off", "--seed", "2")
    try:
        with chromium() as browser, panel(browser, base, token, failed_requests=True) as page:
            page.click("nav [data-tab=robot]")
            page.fill("input[name=url]", f"socket://127.0.0.1:{robot_port}")
            page.fill("input[name=tracker_port]", str(tracker_port))
            page.click("#connect")
            until(page, f"{ROBOT_STATE} === 'disarmed'", timeout=10_000)

            page.check("#follow-plan")
            until(page, "document.querySelectorAll('#plan-job option').length === 2")
            offered = page.eval_on_selector_all(
                "#plan-job option", "(options) => options.map((o) => [o.value, o.disabled, o.textContent])"
            )
            assert [value for value, _disabled, _text in offered] == [str(near_top), str(job)], "newest first"
            assert offered[1][1] is False and '"holds 5" to 1 m' in offered[1][2], offered
            for _value, disabled, text in offered:  # a plan short of its goal is offered disabled, said why
                assert disabled == ("does not reach it" in text), offered
            page.select_option("#plan-job", str(job))
            for name in ("psiL", "zetaL", "psiR", "zetaR", "closed_loop"):
                assert page.is_disabled(f"#robot-run-form [name={name}]"), f"{name}: the plan's, not typed"
            until(page, "document.querySelectorAll('#robot-plan-svg .plan-target').length > 0")
            assert page.locator("#robot-plan-svg .plan-target").count() == len(steps)

            page.once("dialog", lambda dialog: dialog.accept())  # the robot is disarmed: starting arms it
            page.fill("#robot-run-form [name=jumps]", "40")
            page.fill("#robot-run-form [name=max_seconds]", "30")
            page.evaluate(JOURNAL_SEEN)
            page.click("#live-run")
            said(page, f"following plan job {job}")
            until(page, "(document.querySelector('#robot-journal-caption').textContent || '').includes('as stored')",
                  timeout=RUN_WITHIN_MS)  # fmt: skip
            status = httpx.get(f"{base}/api/v1/robot").json()
            assert status["state"] == "disarmed", "every ending disarms"
            stored = httpx.get(f"{base}/api/v1/runs/{status['run']['stored_run_id']}").json()
            results = stored["results"]
            assert stored["world_id"] == world_id and results["plan_job_id"] == job
            assert results["end_reason"].startswith("goal reached"), results["end_reason"]

            seen = page.evaluate("window.__journal")
            live = [count for count, caption in seen if "as stored" not in caption]
            assert live and max(live) >= 3, f"commands shown as they are sent, before the run is stored: {seen}"
            rows = page.eval_on_selector_all("#robot-journal tbody tr", "(rows) => rows.map((r) => r.innerText)")
            assert len(rows) == len(results["commands"]) >= 3, rows
            for row, command in zip(rows, results["commands"], strict=True):
                assert command["leg"] in row and command["why"] in row
                if "target" in command:
                    target = command["target"]
                    assert f"touchdown {target['touchdown']}: {target['side']} segment {target['segment']}" in row, row
            shown = page.text_content("#robot-status")
            assert f"in world {world_id}" in shown and f"following plan job {job}" in shown, shown
            caption = page.text_content("#robot-journal-caption")
            assert f"plan job {job}" in caption and "goal reached" in caption, caption
            assert page.locator("#robot-plan-svg .run-foot").count() == len(results["touchdowns"]) >= 3
            page.set_viewport_size({"width": 1360, "height": 1950})  # the tab whole: status, plan and journal
            page.evaluate("window.scrollTo(0, 0)")
            screenshot(page, "robot_plan_run")
    finally:
        httpx.post(f"{base}/api/v1/robot/disconnect", headers=auth)
        stop_processes(robot)
