// The History tab: runs (filter, sort, pages), experiments, tags and notes, compare, 3D.
import { API, $, say, call, on } from "./api.js";
import { selectTab } from "./tabs.js";
import { describeJob } from "./jobs.js";
import { element, fillTable, attributes } from "./dom.js";
import { VIEWER } from "./view.js";

function runQuery() {
  const form = new FormData($("#history-form"));
  const params = new URLSearchParams();
  for (const name of ["experiment_id", "kind", "tag"]) if (form.get(name)) params.set(name, form.get(name));
  return params;
}

const shownRuns = new Map();  // id -> the run as last listed: what the editor starts from
// The runs ticked in the table (compare, 3D's ghost, calibrate), as last listed.
export const selectedRuns = () => [...document.querySelectorAll("#run-table input:checked")]
  .map((box) => shownRuns.get(Number(box.value))).filter(Boolean);

function runRow(run) {
  const controls = run.controls.map((c) => `${c[0]}°/${c[1]}`).join(", ");
  const select = attributes(element("input", null), { type: "checkbox", value: run.id, "aria-label": `select run ${run.id}` });
  const notes = attributes(element("td", run.notes.length > 60 ? `${run.notes.slice(0, 60)}…` : run.notes), { class: "notes", title: run.notes });
  const actions = attributes(element("td", null,
    attributes(element("button", "edit"), { type: "button", class: "edit-run", "data-run": run.id, "aria-label": `edit the tags and notes of run ${run.id}` }), " ",
    attributes(element("button", "3D"), { type: "button", class: "open-3d", "data-run": run.id, "aria-label": `open run ${run.id} in the 3D view` }), " ",
    attributes(element("a", "share"), { href: `${API}/runs/${run.id}/share.html`, download: "", "aria-label": `share run ${run.id} as a standalone HTML file` }),
    ...recordingLink(run)),
  { class: "actions" });
  const row = element("tr", null, element("td", null, select), element("td", String(run.id)), element("td", run.kind),
    element("td", controls), element("td", `${run.jumps_completed}/${run.jumps}`), element("td", run.climb.toFixed(3)),
    element("td", run.failure_code ?? ""), attributes(element("td", run.tags.join(" ")), { class: "tags" }), notes,
    element("td", new Date(run.created_at).toLocaleString()), actions);
  row.id = `run-${run.id}`;
  return row;
}

// A robot or replay run that has ended downloads as an MCAP recording (Foxglove, Rerun open it),
// and shows its touchdowns beside the model's predictions (touchdowns.js).
export const RECORDED_KINDS = ["robot", "replay"];
function recordingLink(run) {
  if (!RECORDED_KINDS.includes(run.kind) || run.status === "running") return [];
  return [" ", attributes(element("a", "MCAP"), { href: `${API}/runs/${run.id}/export.mcap`, download: "", class: "export-mcap",
    "aria-label": `download run ${run.id} as an MCAP recording (Foxglove, Rerun)` }), " ",
  attributes(element("button", "touchdowns"), { type: "button", class: "show-touchdowns", "data-run": run.id,
    "aria-label": `run ${run.id}'s touchdowns, measured and predicted` })];
}

let listing = 0;  // the newest listing asked for: an older answer arriving later is not shown
export async function loadRuns() {
  const asked = ++listing;
  const params = runQuery();
  const sort = new FormData($("#history-form")).get("sort");
  const page = await call("GET", `/runs?limit=100&sort=${sort}&${params}`);
  if (asked !== listing) return;  // the tab's first listing answered after the filter's
  $("#export-csv").href = `${API}/runs/export?format=csv&${params}`;
  $("#export-json").href = `${API}/runs/export?format=json&${params}`;
  shownRuns.clear();
  page.items.forEach((run) => shownRuns.set(run.id, run));
  fillTable("#run-table", page.items.map(runRow), "No runs match these filters.");
}

on("#history-form", "submit", (event) => { event.preventDefault(); loadRuns(); });
on("#history-form select[name=sort]", "change", () => loadRuns());  // a new order applies at once

// Experiments group runs (and jobs) under a name; picking one filters the runs below.
export async function loadExperiments() {
  const page = await call("GET", "/experiments?limit=100");
  const filter = $("#experiment-filter");
  const chosen = filter.value;
  filter.replaceChildren(new Option("any", ""), ...page.items.map((e) => new Option(`${e.id}: ${e.name}`, String(e.id))));
  filter.value = page.items.some((e) => String(e.id) === chosen) ? chosen : "";
  for (const choice of document.querySelectorAll("select.experiment-choice")) {
    const kept = choice.value;
    choice.replaceChildren(new Option("none", ""), ...page.items.map((e) => new Option(`${e.id}: ${e.name}`, String(e.id))));
    choice.value = page.items.some((e) => String(e.id) === kept) ? kept : "";
  }
  fillTable("#experiment-table", page.items.map((experiment) => element("tr", null,
    element("td", String(experiment.id)),
    element("td", null, attributes(element("button", experiment.name), { type: "button", class: "show-experiment", "data-experiment": experiment.id })),
    attributes(element("td", experiment.description), { class: "description" }), element("td", String(experiment.runs)),
    attributes(element("td", experiment.tags.join(" ")), { class: "tags" }), element("td", new Date(experiment.created_at).toLocaleString()))),
    "No experiments yet: name one above.");
}

loadExperiments().catch(() => {});  // the forms' "in experiment" choices, from the start

on("#experiment-table", "click", async (event) => {
  const button = event.target.closest("button.show-experiment");
  if (!button) return;
  $("#experiment-filter").value = button.dataset.experiment;
  await Promise.all([loadRuns(), showExperimentJobs(button.dataset.experiment, button.textContent)]);
});

// An experiment's jobs, under the experiments (its runs are the runs list, filtered to it).
async function showExperimentJobs(id, name) {
  const page = await call("GET", `/jobs?limit=100&experiment_id=${id}`);
  const table = $("#experiment-jobs");
  table.querySelector("caption").textContent = `Jobs in experiment ${id}: ${name}`;
  fillTable("#experiment-jobs", page.items.map((job) => element("tr", null, element("td", String(job.id)), element("td", job.kind),
    element("td", describeJob(job)), element("td", job.state))), "No jobs in this experiment.");
  table.hidden = false;
}

on("#experiment-form", "submit", async (event) => {
  event.preventDefault();
  const form = new FormData(event.target);
  const experiment = await call("POST", "/experiments", { name: String(form.get("name")), description: String(form.get("description")) });
  event.target.reset();
  await loadExperiments();
  say(`Experiment ${experiment.id} "${experiment.name}" created; runs and jobs join it through experiment_id.`);
});

// Tags and notes: the only things about a run that change after it is stored.
on("#run-table", "click", (event) => {
  const button = event.target.closest("button.edit-run");
  if (!button) return;
  const run = shownRuns.get(Number(button.dataset.run));
  const editor = $("#run-editor");
  editor.dataset.run = run.id;
  $("#run-editor-title").textContent = `Run ${run.id}: tags and notes`;
  $("#run-editor-form").elements.tags.value = run.tags.join(" ");
  $("#run-editor-form").elements.notes.value = run.notes;
  editor.returnValue = "";  // Escape keeps the last returnValue: start each edit from none
  editor.showModal();
});

on("#run-editor", "close", async () => {
  const editor = $("#run-editor");
  const choice = editor.returnValue;
  editor.returnValue = "";
  if (choice !== "save") return;
  const form = $("#run-editor-form").elements;
  const id = Number(editor.dataset.run);
  const tags = form.tags.value.split(/[\s,]+/).filter(Boolean);
  try {
    const run = await call("PATCH", `/runs/${id}`, { tags, notes: form.notes.value });
    shownRuns.set(run.id, run);
    $(`#run-${run.id}`)?.replaceWith(runRow(run));
    say(`Run ${run.id} saved.`);
  } catch (error) {
    editor.showModal();  // keep what was typed; the message above says which field to fix
    throw error;
  }
});

// "3D" on a run: replay it in the 3D view (with the other selected run, if one, as a ghost).
on("#run-table", "click", async (event) => {
  const button = event.target.closest("button.open-3d");
  if (!button) return;
  const runId = Number(button.dataset.run);
  const others = [...document.querySelectorAll("#run-table input:checked")].map((box) => Number(box.value)).filter((id) => id !== runId);
  await call("POST", "/view/replay", { viewer: VIEWER, run_id: runId, overlay_run_id: others[0] ?? null });
  selectTab("view3d");
  say(`Run ${runId} is on the 3D view's timeline${others.length ? ` with run ${others[0]} as a ghost` : ""}.`);
});

// Compare in a person's terms: legs by side, dates in local time, numbers to 6 significant digits.
const LEG_SIDES = ["left", "right"];
const COMPARE_LABELS = { created_at: "created", duration_s: "computed in [s]", climb: "climb [l0]",
  start_xdot: "start xdot [√(g l0)]", start_ydot: "start ydot [√(g l0)]", jumps_completed: "jumps completed",
  failure_code: "failure", code_version: "code version", experiment_id: "experiment" };
function compareLabel(field) {
  if (COMPARE_LABELS[field]) return COMPARE_LABELS[field];
  return field.replace(/^leg(\d+)\./, (_, leg) => `${LEG_SIDES[Number(leg)] ?? `leg ${leg}`} leg `).replace(/^model\./, "model ");
}
function compareValue(field, value) {
  if (value === null || value === undefined || value === "") return "—";
  if (field === "created_at") return new Date(value).toLocaleString();
  if (typeof value === "number" && !Number.isInteger(value)) return String(Number(value.toPrecision(6)));
  return String(value);
}

on("#compare", "click", async () => {
  const ids = [...document.querySelectorAll("#run-table input:checked")].map((box) => box.value);
  if (ids.length < 2) return say("Select two or more runs to compare.", "error");
  const result = await call("GET", `/runs/compare?${ids.map((id) => `ids=${id}`).join("&")}`);
  // Every value (notes included) goes in as text, never as markup.
  const table = element("table", null, element("caption", "What differs"));
  table.id = "compare-table";
  table.append(element("tr", null, element("th", "field"), ...result.runs.map((r) => element("th", `run ${r.id}`))));
  for (const field of result.fields.filter((f) => f !== "id")) {
    const cells = result.runs.map((r) => element("td", compareValue(field, r[field])));
    const row = element("tr", null, element("td", compareLabel(field)), ...cells);
    row.className = "differs";
    table.append(row);
  }
  $("#compare-out").replaceChildren(table);
});
