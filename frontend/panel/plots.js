// Plotly charts: one config (nothing leaves for Plotly's cloud) and layout, the sweep and the
// basin of attraction.

// Every plot's config: nothing leaves for Plotly's cloud (v4's "Share chart..." button is on by
// default), no Chart Studio link, no Plotly logo linking out.
export const PLOT_CONFIG = Object.freeze({
  responsive: true, displaylogo: false, showLink: false, showSendToCloud: false, showEditInChartStudio: false,
  modeBarButtonsToRemove: Object.freeze(["sendChartToCloud", "sendDataToCloud", "editInChartStudio"]),
});

// A plot's box is hidden (index.html) until there is something to draw in it: shown, then drawn
// (Plotly sizes a hidden box wrongly). ``target``: the box's id.
export function draw(target, traces, plotLayout) {
  document.getElementById(target).hidden = false;
  return Plotly.react(target, traces, plotLayout, PLOT_CONFIG);
}

export const layout = (title, x, y, extra = {}) => ({
  title: { text: title, font: { size: 14 } }, margin: { l: 55, r: 15, t: 40, b: 45 },
  xaxis: { title: { text: x } }, yaxis: { title: { text: y } }, ...extra,
});

export function plotSweep(target, result, title) {
  const points = result.points.filter((p) => p.found);
  const stable = points.filter((p) => p.stable);
  const unstable = points.filter((p) => !p.stable);
  const traces = [
    { x: points.map((p) => p.zeta0), y: points.map((p) => p.climb_per_jump), mode: "lines", name: "climb per jump [l0]", line: { color: "#2c6fb7" } },
    { x: stable.map((p) => p.zeta0), y: stable.map((p) => p.max_abs_eigenvalue), mode: "markers", name: "max |λ|, stable", yaxis: "y2", marker: { color: "#2a9d4b", size: 7 } },
    { x: unstable.map((p) => p.zeta0), y: unstable.map((p) => p.max_abs_eigenvalue), mode: "markers", name: "max |λ|, unstable", yaxis: "y2", marker: { color: "#d61f1f", size: 7, symbol: "circle-open" } },
  ];
  const largest = Math.max(...points.map((p) => p.basin_area ?? 0));
  if (largest > 0) {  // dimensionless like |λ|, so it shares the right axis
    traces.push({ x: points.map((p) => p.zeta0), y: points.map((p) => p.basin_area / largest), mode: "lines", name: `basin area ÷ ${largest.toFixed(2)} g l0`,
      yaxis: "y2", line: { color: "#9467bd", dash: "dot" } });
  }
  const inPlace = result.in_place_zeta0.map((z) => ({ type: "line", x0: z, x1: z, yref: "paper", y0: 0, y1: 1, line: { color: "#888", dash: "dash" } }));
  const unit = { type: "line", xref: "paper", x0: 0, x1: 1, yref: "y2", y0: 1, y1: 1, line: { color: "#d61f1f", width: 1, dash: "dot" } };
  draw(target, traces, layout(title, "zeta0 [l0] (smaller: more energy)", "climb per jump [l0]", {
    yaxis2: { title: { text: "max |λ|, basin area" }, overlaying: "y", side: "right", range: [0, 1.15], dtick: 0.25, showgrid: false },
    shapes: [...inPlace, unit], legend: { orientation: "h", y: -0.32 }, margin: { l: 55, r: 55, t: 40, b: 105 },
  }));
}

// Failures in the basin: one grey per kind, each named in the legend (plotly heatmaps have no
// legend entry of their own, so a marker of the same grey stands in for each).
const FAILURE_GREYS = ["#6b7280", "#c4c9d1", "#3f4650", "#9aa1ab", "#e3e6ea"];
const FAILURE_WORDS = { slip: "slips", collapse: "leg collapses", no_liftoff: "no lift-off", no_flight: "no flight", invalid_state: "invalid state", floor: "fell to the floor", no_touchdown: "no touchdown" };
// Undecided cells (neither converged nor failed within the jump limit) in a colour of their own:
// neither a failure's grey nor on the jumps' scale. The result counts the falling ones among them
// (faster than sim_core's FALLING_SPEED: no limit decides them) but does not say which cells.
const UNDECIDED_COLOUR = "#e377c2";

// A heatmap of one colour over the cells where ``where(row, column)`` holds, and its legend entry
// (one legend group: a click on the entry hides the cells too).
function patch(xs, ys, cells, where, colour, name, hover) {
  return [{ type: "heatmap", x: xs, y: ys, z: cells.map((row, i) => row.map((_, j) => (where(i, j) ? 1 : null))), legendgroup: name,
    colorscale: [[0, colour], [1, colour]], showscale: false, name, hovertemplate: `xdot %{x:.3f}, ydot %{y:.3f}: ${hover}<extra></extra>` },
  { x: [null], y: [null], mode: "markers", name, legendgroup: name, marker: { symbol: "square", size: 12, color: colour } }];
}

// A log colour bar's ticks from ``low`` to ``top`` jumps (1, 2, 5, 10, 20, 50, …), at their log10.
function logTicks(low, top) {
  const values = [];
  for (let decade = 1; decade <= top; decade *= 10) values.push(...[1, 2, 5].map((m) => m * decade).filter((v) => v >= low && v <= top));
  return { tickvals: values.map(Math.log10), ticktext: values.map(String) };
}

// The convergence test in words: the first cap, the jump limit the undecided cells went on to, and
// how many are still undecided (``undecided``), how many of those falling where the result says.
function capWords(result, undecided) {
  const cap = Number(result.jumps), limit = Number(result.jump_limit ?? cap);
  const test = limit > cap ? `cap ${cap}, limit ${limit} jumps` : `cap ${cap} jumps, not continued`;
  const falling = Number.isInteger(result.falling) && result.falling > 0 ? ` (${result.falling} falling)` : "";
  return { limit, words: `${test}; ${undecided} cell${undecided === 1 ? "" : "s"} undecided${falling}` };
}

export function plotBasin(target, result, title, start) {
  const [x0, x1] = result.xdot_range, [y0, y1] = result.ydot_range, n = result.grid;
  const axis = (low, high) => Array.from({ length: n }, (_, i) => low + (high - low) * i / (n - 1));
  const xs = axis(x0, x1), ys = axis(y0, y1);
  const codes = result.failure_codes, jumps = result.jumps_to_converge, failure = result.failure;
  const isUndecided = (i, j) => jumps[i][j] < 0 && !failure[i][j];
  const undecided = Number.isInteger(result.undecided) ? result.undecided  // a result from before jump limits: counted here
    : jumps.reduce((sum, row, i) => sum + row.filter((_, j) => isUndecided(i, j)).length, 0);
  const { limit, words } = capWords(result, undecided);
  const kinds = [...new Set(failure.flat().filter(Boolean))].sort((a, b) => a - b);
  const traces = [];
  kinds.forEach((kind, i) => {
    const named = FAILURE_WORDS[codes[String(kind)]] ?? codes[String(kind)];
    traces.push(...patch(xs, ys, failure, (r, c) => failure[r][c] === kind, FAILURE_GREYS[i % FAILURE_GREYS.length], `fails: ${named}`, `fails (${named})`));
  });
  if (undecided > 0) {
    traces.push(...patch(xs, ys, jumps, isUndecided, UNDECIDED_COLOUR, "undecided at the limit", `undecided after ${limit} jumps`));
  }
  // One log colour scale over the jumps to converge that occur (0 jumps, a start already on the
  // orbit, drawn as 1), a factor of 2 at least.
  const converged = jumps.flat().filter((v) => v >= 0).map((v) => Math.max(v, 1));
  const low = converged.length ? converged.reduce((least, v) => Math.min(least, v)) : 1;
  const top = converged.reduce((most, v) => Math.max(most, v), 2 * low);
  traces.push({ type: "heatmap", x: xs, y: ys, z: jumps.map((row) => row.map((v) => (v < 0 ? null : Math.log10(Math.max(v, 1))))),
    text: jumps.map((row) => row.map((v) => (v < 0 ? "" : `${v} jumps`))), zmin: Math.log10(low), zmax: Math.log10(top),
    colorscale: "Viridis", reversescale: true, name: "converges",
    colorbar: { title: { text: "jumps to<br>converge<br>(log scale)" }, ...logTicks(low, top) },
    hovertemplate: "xdot %{x:.3f}, ydot %{y:.3f}: converges in %{text}<extra></extra>" });
  traces.push({ x: [result.gait.state[0]], y: [result.gait.state[1]], mode: "markers", name: `period-${result.gait.period} gait`, legendgroup: "gait", marker: { symbol: "x", size: 12, color: "#d61f1f" } });
  if (start) traces.push({ x: [start.xdot], y: [start.ydot], mode: "markers", name: "start", legendgroup: "start", marker: { symbol: "circle-open", size: 12, color: "#111" } });
  draw(target, traces, layout(`${title}: ${(100 * result.fraction).toFixed(1)} % converge<br>${words}`, "xdot at the section [sqrt(g l0)]", "ydot [sqrt(g l0)]",
    // Grouped, each entry its own group: a row holds as many entries as their own widths allow.
    { legend: { orientation: "h", y: -0.22, traceorder: "grouped", tracegroupgap: 0 }, margin: { l: 55, r: 15, t: 60, b: 115 }, height: 420 }));
}
