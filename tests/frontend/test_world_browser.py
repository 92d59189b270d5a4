"""The World tab (issue 43) in headless Chromium against the real service: a world made from a named
one, listed and drawn (its sides coloured by friction, footholds ticked by their inclination), a
vertex dragged and saved as a new world (the stored one unchanged), a segment's friction set and a
foothold added and removed, a 422 shown at the segment it names, rename and delete (refused while a
run uses the world), a run simulated in a world, and History filtered by world with thumbnails.

Set PARKOUR_SCREENSHOTS=1 to refresh docs/screenshots/world_*.png and history_by_world.png.
"""

import json

import httpx
import pytest

from tests.frontend.browser import chromium, panel, said, screenshot, until
from tests.helpers import served

pytestmark = pytest.mark.slow  # a browser and a service: ~30 s

SEGMENTS = "document.querySelectorAll('#world-svg line.world-segment')"
TEXT = "JSON.parse(document.querySelector('#world-json').value)"


@pytest.fixture(scope="module")
def service(tmp_path_factory):
    data = tmp_path_factory.mktemp("worlds") / "data"
    with served(data, "--no-view") as base_and_token:
        yield base_and_token


@pytest.fixture(scope="module")
def page(service):
    base, token = service
    with chromium() as browser, panel(browser, base, token) as view:
        yield view


def _api(service, method, path, **kwargs):
    base, token = service
    response = httpx.request(method, f"{base}/api/v1{path}", headers={"Authorization": f"Bearer {token}"}, **kwargs)
    response.raise_for_status()
    return response.json() if response.content else None


def _tall_screenshot(page, name):
    """The window, tall enough for the whole editor (the drawing, the errors, the JSON, Save)."""
    size = page.viewport_size
    page.set_viewport_size({"width": size["width"], "height": 1240})
    page.evaluate("window.scrollTo(0, 0)")
    try:
        screenshot(page, name)
    finally:
        page.set_viewport_size(size)


def _open_world_tab(page):
    page.click("nav [data-tab=world]")
    until(page, "!document.querySelector('#world').hidden")


def _create_named(page, name, named):
    page.fill("#world-create-form input[name=name]", name)
    page.select_option("#world-source", "named")
    until(page, f"[...document.querySelectorAll('#world-named option')].some((o) => o.value === {named!r})")
    page.select_option("#world-named", named)
    page.click("#world-create")
    said(page, "stored", f'"{name}"')
    until(page, f"document.querySelector('#world-title').textContent.endsWith({name!r})")


def test_a_named_world_is_created_listed_and_drawn(page, service):
    _open_world_tab(page)
    _create_named(page, "stairs", "staircase")
    stored = _api(service, "GET", "/worlds")["items"][0]
    assert stored["name"] == "stairs" and stored["source"] == "named:staircase"
    row = page.locator("#world-table tbody tr", has_text="stairs")
    assert "named:staircase" in row.inner_text() and row.locator("svg line.world-segment").count() > 10  # a thumbnail
    # Every segment drawn, each coloured by its friction: the steps the model's mu (grey), the
    # stretches between them without grip (mu 0: dashed).
    count = sum(len(stored["world"][side]["points"]) - 1 for side in ("left", "right"))
    assert page.evaluate(f"{SEGMENTS}.length") == count
    strokes = page.evaluate(
        f"[...{SEGMENTS}].map((l) => [l.getAttribute('stroke'), l.getAttribute('stroke-dasharray')])"
    )
    mus = [mu for side in ("left", "right") for mu in stored["world"][side]["mu"]]
    assert [dash is not None for _, dash in strokes] == [mu == 0 for mu in mus]
    assert {stroke for (stroke, _), mu in zip(strokes, mus, strict=True) if mu is None} == {"#9a9a9a"}
    # The steps face 20° upward: a tick each, its label saying so.
    steps = sum(mu is None for mu in mus)
    assert page.locator("#world-svg line.world-foothold").count() >= steps
    labels = page.evaluate("[...document.querySelectorAll('#world-svg text.world-beta')].map((t) => t.textContent)")
    assert "+20°" in labels
    assert page.locator("#world-legend text", has_text="friction mu").count() == 1
    assert json.loads(page.input_value("#world-json")) == stored["world"]


def test_a_dragged_vertex_is_saved_as_a_new_world(page, service):
    original = _api(service, "GET", "/worlds")["items"][0]
    vertex = page.locator("#world-svg circle.world-vertex[data-side=left][data-index='3']")
    box = vertex.bounding_box()
    x, y = box["x"] + box["width"] / 2, box["y"] + box["height"] / 2
    page.mouse.move(x, y)
    page.mouse.down()
    for step in range(1, 6):
        page.mouse.move(x - 4 * step, y)
    page.mouse.up()
    moved = page.evaluate(TEXT)["left"]["points"][3]
    before = original["world"]["left"]["points"][3]
    assert moved[0] < before[0] - 0.1 and abs(moved[1] - before[1]) < 0.02, (moved, before)
    assert page.input_value("#world-save-form input[name=name]") == "stairs (edited)"
    _tall_screenshot(page, "world_editor")
    page.click("#world-save")
    said(page, "stored", "stairs (edited)")
    items = _api(service, "GET", "/worlds")["items"]
    assert [item["name"] for item in items] == ["stairs (edited)", "stairs"]
    assert items[0]["world"]["left"]["points"][3] == moved and items[0]["source"] == "posted"
    assert items[1]["world"] == original["world"]  # the stored world never changes
    until(page, "document.querySelector('#world-title').textContent.endsWith('stairs (edited)')")
    assert page.locator("#world-table tbody tr").count() == 2


def test_friction_is_set_and_a_foothold_added_and_removed(page):
    page.click("#world-svg line.world-segment[data-side=right][data-index='0']")
    until(page, "!document.querySelector('#world-segment-form').hidden")
    page.fill("#world-segment-form input[name=mu]", "1.5")
    page.click("#world-set-mu")
    assert page.evaluate(TEXT)["right"]["mu"][0] == 1.5
    stroke = page.get_attribute("#world-svg line.world-segment[data-side=right][data-index='0']", "stroke")
    assert stroke.startswith("rgb(") and stroke != "#9a9a9a"
    points = len(page.evaluate(TEXT)["right"]["points"])
    page.click("#world-add-hold")
    document = page.evaluate(TEXT)["right"]
    assert len(document["points"]) == points + 2 and document["mu"][:3] == [1.5, None, 1.5]
    assert "segment 1" in page.text_content("#world-selected")  # the new foothold, chosen
    page.click("#world-remove-hold")
    document = page.evaluate(TEXT)["right"]
    assert len(document["points"]) == points and document["mu"][0] == 1.5


def test_a_refused_world_is_marked_at_its_segment(page, service):
    document = page.evaluate(TEXT)
    document["left"]["points"][2][1] = document["left"]["points"][1][1] - 0.05  # below the point before it
    page.fill("#world-json", json.dumps(document, indent=1))
    page.fill("#world-save-form input[name=name]", "stairs broken")
    page.click("#world-save")
    said(page, "Save as new world", "world.left.points[2]")
    until(page, "document.querySelector('#world-svg .world-error-mark') !== null")
    # Marked at the segment ending at point 2 (left segment 1), the message beside it, and listed.
    mark = page.locator("#world-svg .world-error-mark")
    segment = page.locator("#world-svg line.world-segment[data-side=left][data-index='1']")
    assert mark.get_attribute("y2") == segment.get_attribute("y2")
    assert page.locator("#world-svg circle.world-vertex.wrong[data-side=left][data-index='2']").count() == 1
    assert "must increase" in page.text_content("#world-svg .world-error-callout")
    assert "world.left.points[2]" in page.text_content("#world-errors")
    _tall_screenshot(page, "world_error")
    assert [item["name"] for item in _api(service, "GET", "/worlds")["items"]] == ["stairs (edited)", "stairs"]


def test_a_run_in_a_world_and_history_by_world(page, service):
    stairs = next(item for item in _api(service, "GET", "/worlds")["items"] if item["name"] == "stairs")
    page.click("nav [data-tab=simulate]")
    until(page, f"[...document.querySelectorAll('#sim-world option')].some((o) => o.value === '{stairs['id']}')")
    page.click("#save-run")  # parallel walls first
    said(page, "stored:")
    page.select_option("#sim-world", str(stairs["id"]))
    page.click("#save-run")
    said(page, f"in world #{stairs['id']}")
    runs = _api(service, "GET", "/runs")["items"]
    assert [run["world_id"] for run in runs] == [stairs["id"], None]
    page.click("nav [data-tab=history]")
    until(page, "document.querySelectorAll('#run-table tbody tr').length === 2")
    page.select_option("#world-filter", str(stairs["id"]))
    until(page, "document.querySelectorAll('#run-table tbody tr').length === 1")
    cell = page.locator("#run-table tbody tr td.col-world")
    until(page, "document.querySelector('#run-table td.col-world .world-name').textContent === 'stairs'")
    assert cell.locator("svg line.world-segment").count() > 10
    assert f"world_id={stairs['id']}" in page.url
    screenshot(page, "history_by_world")
    page.select_option("#world-filter", "")
    until(page, "document.querySelectorAll('#run-table tbody tr').length === 2")
    assert "parallel" in page.locator("#run-table tbody tr").nth(1).locator("td.col-world").inner_text()


def test_rename_and_delete_refused_while_a_run_uses_the_world(page, service):
    _open_world_tab(page)
    stairs = next(item for item in _api(service, "GET", "/worlds")["items"] if item["name"] == "stairs")
    page.click(f"#world-{stairs['id']} button.open-world")
    until(page, "document.querySelector('#world-title').textContent.endsWith('stairs')")
    assert "used by 1 run(s)" in page.text_content("#world-about")
    page.click("#world-delete")
    said(page, f"Delete world #{stairs['id']}", "is used by run")
    page.fill("#world-rename-form input[name=name]", "stairs in use")
    page.click("#world-rename")
    said(page, "is now", "stairs in use")
    assert _api(service, "GET", f"/worlds/{stairs['id']}")["name"] == "stairs in use"
    edited = next(item for item in _api(service, "GET", "/worlds")["items"] if item["name"] == "stairs (edited)")
    page.click(f"#world-{edited['id']} button.open-world")
    until(page, "document.querySelector('#world-title').textContent.endsWith('stairs (edited)')")
    page.click("#world-delete")
    said(page, f"World #{edited['id']} deleted")
    until(page, "document.querySelectorAll('#world-table tbody tr').length === 1")
    assert [item["name"] for item in _api(service, "GET", "/worlds")["items"]] == ["stairs in use"]
