"""The panel's source, read as text (no browser): no HTML sinks, one plot config for every plot.

The browser test (test_panel_browser.py) shows stored markup stays text in each view; these checks
keep the next change from bringing a sink back in a view that test does not open.
"""

import re
from pathlib import Path

import pytest

PANEL = Path(__file__).resolve().parents[2] / "frontend" / "panel"
SOURCES = sorted(PANEL.glob("*.js")) + sorted(PANEL.glob("*.html"))
# Every way JavaScript turns a string into markup (or script) in a document.
SINKS = re.compile(r"innerHTML|outerHTML|insertAdjacentHTML|document\.write|createContextualFragment|DOMParser|srcdoc")


@pytest.mark.parametrize("path", SOURCES, ids=lambda path: path.name)
def test_no_value_reaches_the_page_as_markup(path):
    lines = enumerate(path.read_text().splitlines(), 1)
    hits = [f"{path.name}:{n}: {line.strip()}" for n, line in lines if SINKS.search(line)]
    assert not hits, f"build elements with element()/attributes() (textContent), never from markup: {hits}"


def _calls(source: str, name: str) -> list[str]:
    """The text of every call ``name(...)`` in ``source``, up to its closing parenthesis."""
    calls = []
    for match in re.finditer(re.escape(name) + r"\(", source):
        depth, end = 0, match.end() - 1
        for end in range(match.end() - 1, len(source)):
            depth += {"(": 1, ")": -1}.get(source[end], 0)
            if depth == 0:
                break
        calls.append(source[match.start() : end + 1])
    return calls


def test_every_plot_gets_the_config_without_cloud_buttons():
    source = "\n".join(path.read_text() for path in sorted(PANEL.glob("*.js")))
    calls = [call for name in ("Plotly.react", "Plotly.newPlot", "Plotly.plot") for call in _calls(source, name)]
    # plots.js's draw(target, data, layout) shows a plot's box and passes PLOT_CONFIG (one of the calls above).
    drawn = [call for call in _calls(source, "draw") if not call.startswith("draw(target, traces, plotLayout")]
    assert len(calls) + len(drawn) >= 7, "the Simulate, Jobs and Robot tabs' plots"
    missing = [call.splitlines()[0] for call in calls if not re.sub(r"\s+", " ", call).endswith(", PLOT_CONFIG)")]
    assert not missing, f"every plot: Plotly.react(target, data, layout, PLOT_CONFIG): {missing}"
    assert "return Plotly.react(target, traces, plotLayout, PLOT_CONFIG);" in source
    config = re.search(r"export const PLOT_CONFIG = Object\.freeze\(\{(.*?)\}\);", source, re.S).group(1)
    for setting in ("displaylogo: false", "showLink: false", "showSendToCloud: false", "showEditInChartStudio: false"):
        assert setting in config
    for button in ("sendChartToCloud", "sendDataToCloud", "editInChartStudio"):
        assert f'"{button}"' in config.split("modeBarButtonsToRemove", 1)[1]


@pytest.mark.parametrize("form", ["sim-form", "job-form", "robot-run-form", "connect-form"])
def test_the_checked_forms_hold_no_second_copy_of_the_ranges(form):
    """Their ranges come from the API's OpenAPI document (fields.js), one source: a hand-written
    min/max here would drift from it, and the browser's own checks (required, min, max) would
    answer before the panel could mark the field in its words."""
    page = (PANEL / "index.html").read_text()
    start = page.index(f'<form id="{form}"')
    markup = page[start : page.index("</form>", start)]
    assert "novalidate" in markup.split(">", 1)[0]
    assert not re.search(r"<input[^>]*\s(min|max|required)(=|\s|>)", markup), "ranges only from the schema"


def test_the_panel_is_modules_of_a_few_hundred_lines_each():
    """An API module, one per tab, plots, the page's text-only DOM building, the field checks, and
    main.js wiring them: loaded as ES modules with no build step, each a few hundred lines."""
    page = (PANEL / "index.html").read_text()
    assert '<script type="module" src="main.js"></script>' in page
    sizes = {path.name: len(path.read_text().splitlines()) for path in PANEL.glob("*.js")}
    assert {"api.js", "simulate.js", "jobs.js", "history.js", "robot.js", "view.js", "plots.js"} <= set(sizes)
    assert max(sizes.values()) <= 300, sizes
    for path in PANEL.glob("*.js"):
        imported = re.findall(r'^import .*?from "\./([\w-]+\.js)";$', path.read_text(), re.M)
        assert all((PANEL / name).exists() for name in imported), (path.name, imported)
