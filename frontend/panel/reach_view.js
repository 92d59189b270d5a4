// A reach job's result in the Jobs tab (backend/jobs/reach.py: ``parkour reach --json`` on a
// stored world): the highest foot each symmetric schedule psi0:zeta0 reached, in metres, as a
// heatmap over psi0 (x) and zeta0 (y) with each cell's ending in its hover text, and the endings
// counted in words. Every value reaches the page as text (the summary's textContent) or as Plotly
// data; a string Plotly shows is escaped first (it reads a few tags in text: <br>, <b>).
import { $ } from "./api.js";
import { draw, layout } from "./plots.js";

const SUMMARY = "#job-summary";
// Each ending in words: sim_core.world.reach's top and capped, and the failures' codes.
const ENDINGS = {
  top: "reached the top", capped: "did every jump below the top", floor: "fell to the floor", slip: "slipped",
  collapse: "collapsed the leg", no_liftoff: "did not lift off", no_flight: "had no flight", invalid_state: "reached an invalid state",
  no_touchdown: "found no touchdown",
};
const ESCAPED = { "<": "&lt;", ">": "&gt;", "&": "&amp;" };
const plotText = (value) => String(value).replace(/[<>&]/g, (character) => ESCAPED[character]);
export const endingWords = (code) => ENDINGS[code] ?? String(code).replaceAll("_", " ");
const metres = (value) => (typeof value === "number" && Number.isFinite(value) ? `${value.toFixed(3)} m` : "—");

// The cell whose foot got highest: {row, column, value} (the first of equals), or null on an empty grid.
function highestCell(highest) {
  let best = null;
  highest.forEach((row, i) => row.forEach((value, j) => {
    if (typeof value === "number" && (best === null || value > best.value)) best = { row: i, column: j, value };
  }));
  return best;
}

// The result in words: the grid, how its cells ended (counted, none left out but the endings no cell had)
// and the highest foot with its schedule.
export function reachWords(id, result) {
  const l0 = Number(result.l0_m);
  const cells = result.psi0_deg.length * result.zeta0.length;
  const counted = Object.entries(result.outcomes ?? {}).filter(([, count]) => count > 0)
    .map(([code, count]) => `${count} ${endingWords(code)}`);
  const best = highestCell(result.highest);
  const where = best ? ` Highest foot ${metres(best.value * l0)} (${best.value.toFixed(3)} l0) at psi0 ${result.psi0_deg[best.column]}°, ` +
    `zeta0 ${result.zeta0[best.row]}: ${endingWords(result.ending[best.row][best.column])}.` : "";
  return `Job ${id}: ${cells} schedule(s) (${result.psi0_deg.length} psi0 × ${result.zeta0.length} zeta0) in "${result.world}", ` +
    `up to ${result.jumps} jumps each, the world's top at ${metres(result.top * l0)}: ${counted.join(", ") || "no cells"}.${where}`;
}

export function showReach(id, result) {
  const summary = $(SUMMARY);
  summary.textContent = reachWords(id, result);
  summary.hidden = false;
  const l0 = Number(result.l0_m);
  const text = result.ending.map((row, i) => row.map((code, j) => plotText(`${endingWords(code)} after ${result.completed[i][j]} jump(s)`)));
  draw("job-plot", [{
    type: "heatmap", x: result.psi0_deg, y: result.zeta0, z: result.highest.map((row) => row.map((value) => value * l0)), text,
    colorscale: "Viridis", colorbar: { title: { text: "highest<br>foot [m]" } }, name: "highest foot",
    hovertemplate: "psi0 %{x}°, zeta0 %{y}: highest foot %{z:.3f} m; %{text}<extra></extra>",
  }], layout(`Job ${id}: the highest foot of each schedule [m] (the top at ${metres(result.top * l0)})`, "psi0 [deg]", "zeta0 [l0]"));
}
