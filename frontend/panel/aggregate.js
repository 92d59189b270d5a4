// History → "Group runs": the runs the filters select, grouped by a parameter (GET
// /api/v1/runs/aggregate, computed in SQL): per group the runs, and the climb and jumps completed
// as mean ± std with the mean's 95% confidence interval — e.g. a setting's seeds together — drawn
// as means with their intervals. Every value reaches the page as text.
import { $, call } from "./api.js";
import { element, attributes, fillTable } from "./dom.js";
import { PLOT_CONFIG, layout } from "./plots.js";

export const GROUP_BY = {
  zeta0: "zeta0 of the first leg [l0]", psi0_deg: "psi0 of the first leg [deg]", alpha: "alpha", target: "target [m]",
  kind: "kind", status: "status", end_reason: "end reason", loop: "loop", controller: "controller", tag: "tag",
  experiment_id: "experiment", failure_code: "failure",
};
const CONTINUOUS = ["zeta0", "psi0_deg", "alpha", "target"];
const OUTCOMES = [["climb", "climb [l0]"], ["jumps_completed", "jumps completed"]];

const digits = (value, count = 4) => (value === null || value === undefined ? "—" : String(Number(Number(value).toPrecision(count))));
const interval = (stats) => (stats.ci95_low === null ? "—" : `${digits(stats.ci95_low)} … ${digits(stats.ci95_high)}`);
const keyText = (group, by) => {
  if (group.key === null) return by === "end_reason" ? "(simulations, replays)" : "(none)";
  if (group.low !== null && group.low !== undefined) return `${digits(group.low)} – ${digits(group.high)}`;
  return typeof group.key === "number" ? digits(group.key, 6) : String(group.key);
};

let asked = 0;  // the latest grouping asked for: an older answer arriving later is not shown

// Group the runs that ``filters`` (URLSearchParams of the run filters) select by ``by``, in
// ``bins`` equal bins where given (continuous parameters).
export async function showAggregate(filters, by, bins) {
  const query = new URLSearchParams(filters);
  query.set("by", by);
  if (bins && CONTINUOUS.includes(by)) query.set("bins", bins);
  const mine = ++asked;
  const result = await call("GET", `/runs/aggregate?${query}`);
  if (mine !== asked) return result;
  $("#aggregate-box").hidden = false;
  const total = result.groups.reduce((sum, group) => sum + group.runs, 0);
  $("#aggregate-table caption").textContent = `${total.toLocaleString()} runs grouped by ${GROUP_BY[by]}`
    + `${result.bins ? ` in ${result.bins} bins` : ""}: mean ± std, and the mean's 95% confidence interval`;
  fillTable("#aggregate-table", result.groups.map((group) => element("tr", null,
    attributes(element("td", keyText(group, by)), { class: "key" }), element("td", group.runs.toLocaleString()),
    ...OUTCOMES.flatMap(([name]) => [element("td", `${digits(group[name].mean)} ± ${digits(group[name].std, 3)}`),
      attributes(element("td", interval(group[name])), { class: "ci" })]))), "No runs match these filters.");
  drawGroups(result, by);
  return result;
}

export function hideAggregate() {
  asked += 1;
  $("#aggregate-box").hidden = true;
}

function drawGroups(result, by) {
  if (typeof Plotly === "undefined" || !result.groups.length) return;
  const numeric = CONTINUOUS.includes(by) || by === "experiment_id";
  const x = result.groups.map((group) => (numeric ? group.key : keyText(group, by)));
  const traces = OUTCOMES.map(([name, words], k) => ({
    x, y: result.groups.map((group) => group[name].mean), name: `${words}, mean`, type: "scatter",
    mode: numeric ? "lines+markers" : "markers", yaxis: k ? "y2" : "y", marker: { size: 8 },
    error_y: { type: "data", symmetric: false, visible: true,
      array: result.groups.map((group) => (group[name].ci95_high === null ? 0 : group[name].ci95_high - group[name].mean)),
      arrayminus: result.groups.map((group) => (group[name].ci95_low === null ? 0 : group[name].mean - group[name].ci95_low)) },
    text: result.groups.map((group) => `${group.runs} runs`),
    hovertemplate: `%{x}: ${words} %{y:.4g} (%{text})<extra></extra>`,
  }));
  Plotly.react("aggregate-plot", traces, layout(`Outcomes by ${GROUP_BY[by]} (bars: 95% interval of the mean)`, GROUP_BY[by],
    "climb [l0]", { yaxis2: { title: { text: "jumps completed" }, overlaying: "y", side: "right", showgrid: false },
      legend: { orientation: "h", y: -0.3 }, margin: { l: 55, r: 55, t: 40, b: 95 },
      xaxis: { title: { text: GROUP_BY[by] }, type: numeric ? "linear" : "category" } }), PLOT_CONFIG);
}
