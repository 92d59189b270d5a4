// History's compare basket: the runs picked for Compare, the 3D view's ghost, Calibrate and the
// parameter-vs-outcome plot. It outlives pages and filters (a run stays in it until removed), and
// the address bar names it (history_view.js), so a link brings it back. Every value from the API
// reaches the page as text (dom.js).
import { API, $, say, call, on } from "./api.js";
import { element, attributes } from "./dom.js";
import { PLOT_CONFIG, layout } from "./plots.js";

export const MAX_BASKET = 50;  // what Compare takes at once (GET /runs/compare)
const runs = new Map();  // id -> the run as last listed (RunOut's fields), in the order they were added
let changed = () => {};

// ``callback()`` after each change (history.js: the address bar, the table's ticks).
export function onBasketChange(callback) { changed = callback; }
export const basketIds = () => [...runs.keys()];
export const basketRuns = () => [...runs.values()];
export const inBasket = (id) => runs.has(id);
// The basket as run filters (``ids=3&ids=7``): its export and grouping are of these runs alone.
export const basketQuery = () => new URLSearchParams(basketIds().map((id) => ["ids", String(id)]));

export function addRun(run) {
  if (runs.has(run.id)) { runs.set(run.id, run); return true; }
  if (runs.size >= MAX_BASKET) {
    say(`The basket holds at most ${MAX_BASKET} runs (what Compare takes): remove some first.`, "error");
    return false;
  }
  runs.set(run.id, run);
  update();
  return true;
}

export function removeRun(id) {
  if (runs.delete(id)) update();
}

// A run listed again (e.g. edited): its newest fields, where it is in the basket.
export function refreshRun(run) {
  if (runs.has(run.id)) { runs.set(run.id, run); draw(); }
}

export function clearBasket() {
  runs.clear();
  update();
}

// The basket a link names (ids), read back from the API: one call for up to 50 runs.
export async function restoreBasket(ids) {
  ids = ids.slice(0, MAX_BASKET).filter((id) => !runs.has(id));
  if (!ids.length) return;
  let found;
  try {
    if (ids.length < 2) throw new Error("compare takes two or more");
    const compared = await call("GET", `/runs/compare?only_differences=false&${ids.map((id) => `ids=${id}`).join("&")}`);
    found = compared.runs.map(fromRecord);
  } catch {  // one run, or one of them deleted since: each on its own (a missing one is said and left out)
    found = await Promise.all(ids.map((id) => call("GET", `/runs/${id}`).catch(() => null)));
  }
  for (const run of found.filter(Boolean)) runs.set(run.id, run);
  update();
}

// A flat record (``model.alpha``, ``leg0.zeta0`` …: GET /runs/compare) as the basket keeps a run.
function fromRecord(record) {
  const controls = [];
  for (let leg = 0; `leg${leg}.zeta0` in record && record[`leg${leg}.zeta0`] !== null; leg += 1) {
    controls.push([record[`leg${leg}.psi0_deg`], record[`leg${leg}.zeta0`]]);
  }
  const model = Object.fromEntries(Object.entries(record).filter(([key]) => key.startsWith("model."))
    .map(([key, value]) => [key.slice(6), value]));
  return { ...record, controls, model };
}

function update() {
  draw();
  changed();
}

function runLabel(run) {
  const leg = run.controls?.[0];
  return `run ${run.id} · ${run.kind}${leg ? ` · ${leg[0]}°/${leg[1]}` : ""}`;
}

function draw() {
  const box = $("#basket");
  const list = basketRuns();
  $("#basket-count").textContent = list.length ? `${list.length} run${list.length > 1 ? "s" : ""}` : "empty";
  $("#basket-runs").replaceChildren(...list.map((run) => element("li", null,
    attributes(element("span", runLabel(run)), { class: "basket-run" }), " ",
    attributes(element("button", "×"), { type: "button", class: "basket-remove", "data-run": run.id,
      "aria-label": `remove run ${run.id} from the basket`, title: "remove from the basket" }))));
  $("#basket-empty").hidden = list.length > 0;
  $("#basket-export").hidden = $("#basket-group").hidden = !list.length;
  $("#basket-export").href = `${API}/runs/export?format=csv&${basketQuery()}`;  // the basket, not the filter
  box.dataset.count = String(list.length);
  drawPlot();
}

on("#basket-runs", "click", (event) => {
  const button = event.target.closest("button.basket-remove");
  if (button) removeRun(Number(button.dataset.run));
});
on("#basket-clear", "click", () => clearBasket());

// A parameter against an outcome over the basket's runs, one marker per run (its id on hover).
const PARAMETERS = {
  zeta0: ["zeta0 of the first leg [l0]", (run) => run.controls?.[0]?.[1]],
  psi0_deg: ["psi0 of the first leg [deg]", (run) => run.controls?.[0]?.[0]],
  alpha: ["alpha (stiffness, nondimensional)", (run) => run.model?.alpha],
  target: ["closed-loop target [m]", (run) => run.target],
  created_at: ["created", (run) => run.created_at],
};
const OUTCOMES = {
  climb: ["climb [l0]", (run) => run.climb],
  jumps_completed: ["jumps completed", (run) => run.jumps_completed],
  duration_s: ["duration [s]", (run) => run.duration_s],
};

function drawPlot() {
  const target = $("#basket-plot");
  const list = basketRuns();
  $("#basket-plot-box").hidden = list.length === 0;
  if (!list.length || !$("#basket-plot-box").open || typeof Plotly === "undefined") return;
  const [xWords, x] = PARAMETERS[$("#basket-x").value];
  const [yWords, y] = OUTCOMES[$("#basket-y").value];
  const kinds = [...new Set(list.map((run) => run.kind))];
  const traces = kinds.map((kind) => {
    const shown = list.filter((run) => run.kind === kind && x(run) !== null && x(run) !== undefined);
    return { x: shown.map(x), y: shown.map(y), text: shown.map((run) => `run ${run.id}`), mode: "markers", name: kind,
      type: "scatter", marker: { size: 9 }, hovertemplate: `%{text}: ${xWords} %{x}, ${yWords} %{y}<extra></extra>` };
  });
  Plotly.react(target, traces, layout(`Basket: ${yWords} against ${xWords}`, xWords, yWords,
    { legend: { orientation: "h", y: -0.3 }, margin: { l: 55, r: 15, t: 40, b: 90 } }), PLOT_CONFIG);
}

on("#basket-plot-box", "toggle", drawPlot);  // drawn when opened: Plotly cannot size a closed box
on("#basket-x", "change", drawPlot);
on("#basket-y", "change", drawPlot);
