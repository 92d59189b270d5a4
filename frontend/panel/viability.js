// A viability job's results in the Jobs tab (backend/jobs/viability.py): the measure of
// every mid-chute state (the fraction of leg commands that keep the robot going forever; outside
// the kernel none does), and a clicked state's viable commands over (psi0, zeta0), unpacked from
// the result's bits. Every value reaches the page as Plotly data or text.
import { $, say } from "./api.js";
import { draw, layout } from "./plots.js";

const ACTIONS_BOX = "job-plot-actions";
let shown = null;  // { id, result, bits } of the job on show, for clicks

export function hideViability() {
  shown = null;
  const box = document.getElementById(ACTIONS_BOX);
  if (!box.hidden && window.Plotly) Plotly.purge(box);
  box.hidden = true;
}

function unpack(base64) {
  const bytes = Uint8Array.from(atob(base64), (c) => c.charCodeAt(0));
  return (index) => (bytes[index >> 3] >> (7 - (index & 7))) & 1;  // numpy.packbits: big-endian bits
}

export function showViability(id, result) {
  const { xdot, ydot } = result.state_axes;
  // The result's arrays are [xdot index][ydot index]; a heatmap's z is [row = y][column = x].
  const measure = ydot.map((_, j) => xdot.map((_, i) => (result.kernel[i][j] ? result.measure[i][j] : null)));
  const outside = ydot.map((_, j) => xdot.map((_, i) => (result.kernel[i][j] ? null : 1)));
  shown = { id, result, bit: unpack(result.viable_pairs) };
  say(`Job ${id}: ${result.kernel_cells} of ${result.cells} states viable (${(100 * result.kernel_fraction).toFixed(1)}%), ` +
    `mean measure ${result.measure_mean.toFixed(2)} in the kernel; ${result.pairs.toLocaleString("en")} pairs in ${result.seconds.toFixed(1)} s. ` +
    "Click a state for its viable commands.");
  draw("job-plot", [
    { type: "heatmap", x: xdot, y: ydot, z: outside, colorscale: [[0, "#c4c9d1"], [1, "#c4c9d1"]], showscale: false, name: "not viable",
      hovertemplate: "xdot %{x:.3f}, ydot %{y:.3f}: not viable<extra></extra>" },
    { x: [null], y: [null], mode: "markers", name: "not viable: every command fails sooner or later", marker: { symbol: "square", size: 12, color: "#c4c9d1" } },
    { type: "heatmap", x: xdot, y: ydot, z: measure, zmin: 0, zmax: 1, colorscale: "Viridis", name: "viable",
      colorbar: { title: { text: "measure:<br>viable share<br>of commands" } },
      hovertemplate: "xdot %{x:.3f}, ydot %{y:.3f}: %{z:.2f} of commands viable<extra></extra>" },
  ], layout(`Job ${id}: viability kernel and its measure`, "xdot mid-chute [√(g l0)], toward the wall", "ydot mid-chute [√(g l0)]",
    { showlegend: true, legend: { orientation: "h", y: -0.25 }, margin: { l: 55, r: 15, t: 40, b: 95 } }));
  const plot = document.getElementById("job-plot");
  plot.removeAllListeners?.("plotly_click");
  plot.on?.("plotly_click", (event) => {
    const point = event.points[0];
    showActions(xdot.indexOf(point.x), ydot.indexOf(point.y));
  });
}

// One state's commands: viable ones coloured, the rest grey.
export function showActions(i, j) {
  if (!shown || i < 0 || j < 0) return;
  const { id, result, bit } = shown;
  const { psi0_deg: psi0, zeta0 } = result.action_axes;
  const [, ny, np, nz] = result.viable_pairs_shape;
  const base = (i * ny + j) * np * nz;
  const z = zeta0.map((_, b) => psi0.map((_, a) => bit(base + a * nz + b)));
  const count = z.flat().reduce((total, value) => total + value, 0);
  const x = result.state_axes.xdot[i], y = result.state_axes.ydot[j];
  draw(ACTIONS_BOX, [{ type: "heatmap", x: psi0, y: zeta0, z, zmin: 0, zmax: 1, showscale: false,
    colorscale: [[0, "#e3e6ea"], [0.5, "#e3e6ea"], [0.5, "#2a9d4b"], [1, "#2a9d4b"]],
    hovertemplate: "psi0 %{x:.1f}°, zeta0 %{y:.3f}: %{z}<extra></extra>" }],
  layout(`Job ${id}: at xdot ${x.toFixed(3)}, ydot ${y.toFixed(3)}: ${count} of ${psi0.length * zeta0.length} commands viable (green)`,
    "psi0 [deg]", "zeta0 [l0]"));
  $(`#${ACTIONS_BOX}`).setAttribute("data-state", `${i},${j}`);
}
