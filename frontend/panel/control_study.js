// A control-study job's results in the Jobs tab (the result of ``parkour control-study --json``
// plus its ``plots``): a row per controller, failures by jump, the height error once risen, and
// the first climbs. Every value reaches the page as text (dom.js) or as Plotly data.
import { $ } from "./api.js";
import { draw, layout } from "./plots.js";
import { element, fillTable } from "./dom.js";
import { controllerColor } from "./catalog.js";

const cm = (metres) => (metres === null || metres === undefined ? "—" : `${(metres * 100).toFixed(2)} cm`);
const EXTRA_PLOTS = ["job-plot-errors", "job-plot-climbs"];

function row(entry) {
  const codes = Object.entries(entry.failure_codes).map(([code, count]) => `${code.replaceAll("_", " ")} ${count}`).join(", ");
  // Survivors count at the trials' length: then the mean is a lower bound ("≥").
  const lasted = entry.mean_jumps_to_failure === undefined ? "—" : `${entry.survived ? "≥ " : ""}${Math.round(entry.mean_jumps_to_failure)}`;
  return element("tr", null, element("td", entry.name), element("td", `${entry.failures}/${entry.trials}`), element("td", lasted),
    element("td", cm(entry.height_rms_m)), element("td", cm(entry.height_median_abs_m)),
    element("td", entry.rise_jumps === null ? "—" : String(entry.rise_jumps)),
    element("td", `${(100 * entry.saturated_fraction).toFixed(1)}%`), element("td", entry.us_per_jump.toPrecision(3)),
    element("td", codes || "none"));
}

// Hide what a control study showed (another job's results are about to be drawn).
export function hideControlStudy() {
  $("#job-study").hidden = true;
  for (const id of EXTRA_PLOTS) {
    const box = document.getElementById(id);
    if (!box.hidden && window.Plotly) Plotly.purge(box);
    box.hidden = true;
  }
}

export async function showControlStudy(id, result) {
  const [seed0, seeds] = result.seeds;
  const table = $("#job-study");
  table.querySelector("caption").textContent =
    `Job ${id}: ${seeds} trials (seeds ${seed0}–${seed0 + seeds - 1}) × ${result.jumps} jumps to ${result.target_m} m, the same noise for every controller`;
  fillTable("#job-study", result.controllers.map(row), "No controllers.");
  table.hidden = false;
  const plots = result.plots.controllers;
  // Both boxes shown before either is drawn: each takes half the row only once both are shown,
  // and Plotly sizes a plot to its box as it draws.
  for (const id of EXTRA_PLOTS) document.getElementById(id).hidden = false;
  const colors = Object.fromEntries(await Promise.all(plots.map(async (plot) => [plot.name, await controllerColor(plot.name)])));
  const color = (name) => ({ color: colors[name] });
  draw("job-plot", plots.map((plot) => ({
    x: plot.failure_curve.jumps, y: plot.failure_curve.failures, mode: "lines", line: { shape: "hv", ...color(plot.name) }, name: plot.name,
  })), layout(`Job ${id}: trials failed by jump`, "jumps", `trials failed (of ${seeds})`, { yaxis: { title: { text: `trials failed (of ${seeds})` }, rangemode: "tozero" } }));
  draw("job-plot-errors", plots.map((plot) => {
    const edges = plot.height_error_histogram.edges_m;
    return { x: edges.slice(0, -1).map((edge, i) => 50 * (edge + edges[i + 1])), y: plot.height_error_histogram.counts,
      mode: "lines", line: { shape: "hvh", ...color(plot.name) }, name: plot.name };
  }), layout("Height error once risen (the end bins hold what lies beyond)", "target − height [cm]", "touchdowns"));
  const target = { type: "line", xref: "paper", x0: 0, x1: 1, y0: result.target_m, y1: result.target_m, line: { color: "#888", dash: "dash" } };
  draw("job-plot-climbs", plots.flatMap((plot) => plot.examples.map((heights, i) => ({
    y: heights, mode: "lines", name: plot.name, legendgroup: plot.name, showlegend: i === 0, line: { width: 1, ...color(plot.name) },
  }))), layout(`The first ${plots[0]?.examples.length ?? 0} trials' climbs (dashed: the target)`, "touchdown", "body height [m]", {
    shapes: [target], yaxis: { title: { text: "body height [m]" }, range: [-0.05, 1.6 * result.target_m] },  // a failed trial's fall runs off the bottom
  }));
}
