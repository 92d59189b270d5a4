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
const FAILURE_WORDS = { slip: "slips", collapse: "leg collapses", no_liftoff: "no lift-off", no_flight: "no flight", invalid_state: "invalid state" };

export function plotBasin(target, result, title, start) {
  const [x0, x1] = result.xdot_range, [y0, y1] = result.ydot_range, n = result.grid;
  const axis = (low, high) => Array.from({ length: n }, (_, i) => low + (high - low) * i / (n - 1));
  const xs = axis(x0, x1), ys = axis(y0, y1);
  const codes = result.failure_codes;
  const converged = result.jumps_to_converge.map((row) => row.map((jumps) => (jumps < 0 ? null : jumps)));
  const kinds = [...new Set(result.failure.flat().filter(Boolean))].sort((a, b) => a - b);
  const traces = [];
  kinds.forEach((kind, i) => {
    const grey = FAILURE_GREYS[i % FAILURE_GREYS.length], words = FAILURE_WORDS[codes[String(kind)]] ?? codes[String(kind)];
    traces.push({ type: "heatmap", x: xs, y: ys, z: result.failure.map((row) => row.map((code) => (code === kind ? 1 : null))),
      colorscale: [[0, grey], [1, grey]], showscale: false, name: `fails: ${words}`,
      hovertemplate: `xdot %{x:.3f}, ydot %{y:.3f}: fails (${words})<extra></extra>` });
    traces.push({ x: [null], y: [null], mode: "markers", name: `fails: ${words}`, marker: { symbol: "square", size: 12, color: grey } });
  });
  traces.push({ type: "heatmap", x: xs, y: ys, z: converged, colorscale: "Viridis", reversescale: true, name: "converges",
    colorbar: { title: { text: "jumps to<br>converge" } }, hovertemplate: "xdot %{x:.3f}, ydot %{y:.3f}: %{z} jumps<extra></extra>" });
  traces.push({ x: [result.gait.state[0]], y: [result.gait.state[1]], mode: "markers", name: `period-${result.gait.period} gait`, marker: { symbol: "x", size: 12, color: "#d61f1f" } });
  if (start) traces.push({ x: [start.xdot], y: [start.ydot], mode: "markers", name: "start", marker: { symbol: "circle-open", size: 12, color: "#111" } });
  draw(target, traces, layout(`${title}: ${(100 * result.fraction).toFixed(1)} % converge`, "xdot at the section [sqrt(g l0)]", "ydot [sqrt(g l0)]",
    { legend: { orientation: "h", y: -0.32 }, margin: { l: 55, r: 15, t: 40, b: 105 } }));
}
