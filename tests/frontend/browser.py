"""What the browser tests share: headless Chromium through Playwright, a panel page signed in with
the token whose errors and Content-Security-Policy refusals fail the test, and waiting on the page.

A test module importing this is skipped, saying why, where there is no Chromium or no Playwright
(``./test.sh`` installs Debian's Chromium when it can).
"""

from __future__ import annotations

import json
import os
import shutil
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
CHROMIUM = os.environ.get("PARKOUR_CHROMIUM") or shutil.which("chromium") or shutil.which("chromium-browser")
if CHROMIUM is None:
    pytest.skip("no Chromium: ./test.sh installs the Debian package; or set PARKOUR_CHROMIUM", allow_module_level=True)
sync_api = pytest.importorskip("playwright.sync_api")

# WebGL for the 3D view without a GPU: SwiftShader, Chromium's software renderer.
CHROMIUM_ARGS = ["--no-sandbox", "--use-angle=swiftshader", "--enable-unsafe-swiftshader"]
VIEWPORT = {"width": 1360, "height": 900}
# What the Content-Security-Policy refuses (backend/api/security.py), reported by the page.
CSP_LISTENER = """window.__csp_violations = [];
document.addEventListener("securitypolicyviolation", (e) => window.__csp_violations.push(
  `${e.violatedDirective} refused ${e.blockedURI} (${e.sourceFile}:${e.lineNumber})`));"""
TOKEN_ACCEPTED = "document.querySelector('#token-status').dataset.state === 'accepted'"
# Every message the panel shows, kept in the page as it is added (an init script: from each load
# on, reloads too): an "ok" message goes after 4 s, which a loaded machine's test can spend
# between its click and its first look (:func:`said`).
KEEP_MESSAGES = """window.__said = [];
document.addEventListener("DOMContentLoaded", () => {
  const box = document.querySelector("#messages");
  if (box) new MutationObserver((changes) => changes.forEach((change) => change.addedNodes.forEach(
    (node) => window.__said.push(node.textContent)))).observe(box, {childList: true});
});"""


@contextmanager
def chromium() -> Iterator:
    """A headless Chromium, closed afterwards."""
    with sync_api.sync_playwright() as playwright:
        browser = playwright.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_ARGS)
        try:
            yield browser
        finally:
            browser.close()


@contextmanager
def panel(browser, base: str, token: str, *, failed_requests: bool = False) -> Iterator:
    """The panel at ``base`` in a context of its own (its own storage), signed in with ``token``.
    Afterwards, a script error, a CSP refusal or (``failed_requests``) a request that failed other
    than by being aborted on purpose (a finished job's event stream) fails the test."""
    context = browser.new_context(viewport=VIEWPORT)
    context.add_init_script(CSP_LISTENER)
    context.add_init_script(KEEP_MESSAGES)
    page = context.new_page()
    errors = []
    page.on("pageerror", lambda error: errors.append(str(error)))
    page.on("console", lambda message: "Content Security Policy" in message.text and errors.append(message.text))
    if failed_requests:
        page.on(
            "requestfailed",
            lambda request: "ERR_ABORTED" in (request.failure or "") or errors.append(f"failed {request.url}"),
        )
    try:
        page.goto(f"{base}/")
        page.fill("#token", token)
        page.dispatch_event("#token", "change")
        until(page, TOKEN_ACCEPTED)
        yield page
        assert page.evaluate("window.__csp_violations") == [], "the panel runs under its CSP"
        assert not errors, errors
    finally:
        context.close()


def until(page, expression: str, timeout: float = 30_000) -> None:
    """Wait until ``expression`` is true in the page. Not ``page.wait_for_function``: it evaluates
    its predicate in the page with eval, which the panel's CSP (script-src 'self') refuses;
    ``page.evaluate`` goes through the DevTools protocol, which the page's CSP does not govern."""
    deadline = time.monotonic() + timeout / 1000
    while not page.evaluate(expression):
        if time.monotonic() > deadline:
            shown = page.evaluate("[...document.querySelectorAll('.message')].map((m) => m.textContent)")
            pytest.fail(f"not true within {timeout / 1000:g} s: {expression} (messages shown: {shown})")
        time.sleep(0.05)


def said(page, *words: str, timeout: float = 30_000) -> str:
    """Wait until the panel has shown a message with all of ``words`` in it since it loaded (gone
    or not); the latest such. The page's context has :data:`KEEP_MESSAGES`."""
    test = " && ".join(f"text.includes({json.dumps(word)})" for word in words)
    found = f"window.__said.filter((text) => {test}).at(-1)"
    until(page, f"{found} !== undefined", timeout)
    return page.evaluate(found)


def screenshot(page, name: str, selector: str | None = None) -> None:
    """``name``.png of the page's window (or of ``selector``'s element): into docs/screenshots with
    PARKOUR_SCREENSHOTS=1 set, else into /tmp to be looked at."""
    folder = ROOT / "docs" / "screenshots" if os.environ.get("PARKOUR_SCREENSHOTS") else Path("/tmp")
    (page.locator(selector) if selector else page).screenshot(path=str(folder / f"{name}.png"))
