// The History tab: every run, a page at a time from the service (filters, search, sort by any
// column, page size; "runs 51–100 of 1,234"), a compare basket that outlives pages and filters
// (basket.js), columns to show, tags and notes, Compare, 3D, exports; the experiments and an
// experiment's page (experiment.js) and runs grouped by a parameter (aggregate.js). The whole
// view is in the address bar (history_view.js). Every value reaches the page as text (dom.js).
import { API, $, say, call, on } from "./api.js";
import { selectTab } from "./tabs.js";
import { element, fillTable, attributes } from "./dom.js";
import { VIEWER } from "./view.js";
import { FILTERS, COLUMNS, readView, showView } from "./history_view.js";
import { addRun, removeRun, refreshRun, inBasket, basketIds, basketRuns, basketQuery, onBasketChange, restoreBasket } from "./basket.js";
import { loadExperiments, onExperimentRuns, showExperiment, closeExperiment } from "./experiment.js";
import { GROUP_BY, showAggregate, hideAggregate } from "./aggregate.js";
import { cell, controlsText, endingBadge, jumpsCell, statusCell, targetText, worldCell } from "./run_cells.js";
import "./compare.js";

export { loadExperiments };
// A robot or replay run that has ended downloads as an MCAP recording (Foxglove, Rerun open it),
// and shows its touchdowns beside the model's predictions (touchdowns.js); a simulated run stored
// with its path downloads as one too (its path and touchdowns on the same channels), to open beside them.
export const RECORDED_KINDS = ["robot", "replay"];
const exportsMcap = (run) => (RECORDED_KINDS.includes(run.kind) && run.status !== "running")
  || (run.kind === "sim" && run.has_trajectory);
// The runs in the basket (Compare, 3D's ghost, Calibrate: calibration.js), as last listed.
export const selectedRuns = () => basketRuns();

const SORTS = [["-id", "newest"], ["id", "oldest"], ["-climb", "best climb"], ["climb", "least climb"],
  ["zeta0", "zeta0 ↑"], ["-zeta0", "zeta0 ↓"], ["psi0_deg", "psi0 ↑"], ["-psi0_deg", "psi0 ↓"],
  ["-jumps_completed", "most jumps"], ["jumps_completed", "fewest jumps"], ["-duration_s", "longest"], ["duration_s", "shortest"],
  ["-created_at", "created ↓"], ["created_at", "created ↑"], ["kind", "kind"], ["status", "status"], ["end_reason", "ending"],
  ["loop", "loop"], ["controller", "controller"], ["-target", "target ↓"], ["target", "target ↑"], ["failure_code", "failure"]];
const COLUMN_WORDS = { kind: "kind", status: "status", ending: "ending", loop: "loop", controller: "controller", target: "target",
  controls: "controls", world: "world", jumps: "jumps", climb: "climb", failure: "failure", tags: "tags", notes: "notes", created: "created" };
const view = readView();  // what the tab shows; the form holds the filters, sort and page size
const shownRuns = new Map();  // id -> the run as last listed: what the editor and the basket start from
const form = () => $("#history-form");

$("#history-form select[name=sort]").replaceChildren(...SORTS.map(([value, words]) => new Option(words, value)));
$("#aggregate-by").replaceChildren(...Object.entries(GROUP_BY).map(([value, words]) => new Option(words, value)));
$("#run-column-choices").replaceChildren(...COLUMNS.map((name) => element("label", null,
  attributes(element("input", null), { type: "checkbox", name, checked: "" }), ` ${COLUMN_WORDS[name]}`)));
for (const header of document.querySelectorAll("#run-table th[data-sort]")) {  // a header sorts by its column
  header.replaceChildren(attributes(element("button", header.textContent), { type: "button", class: "sort-by", "data-sort": header.dataset.sort,
    title: `sort by ${header.textContent}; again: the other way` }));
}

function formToView() {
  const values = new FormData(form());
  view.filters = {};
  for (const name of FILTERS) if (String(values.get(name) ?? "").trim()) view.filters[name] = String(values.get(name)).trim();
  view.sort = String(values.get("sort"));
  view.size = Number(values.get("size"));
}

function viewToForm() {
  const fields = form().elements;
  for (const name of FILTERS) {
    const field = fields[name], value = view.filters[name] ?? "";
    if (field.tagName === "SELECT" && value && ![...field.options].some((option) => option.value === value)) {
      field.append(new Option(value, value));  // e.g. an experiment before the list of them has loaded
    }
    field.value = value;
  }
  if (!SORTS.some(([value]) => value === view.sort)) view.sort = "-id";
  fields.sort.value = view.sort;
  fields.size.value = String(view.size);
}

const filterQuery = () => new URLSearchParams(view.filters);

function runRow(run) {
  const tick = attributes(element("input", null), { type: "checkbox", value: run.id, "aria-label": `run ${run.id} in the compare basket` });
  tick.checked = inBasket(run.id);
  const notes = attributes(element("td", run.notes.length > 60 ? `${run.notes.slice(0, 60)}…` : run.notes), { class: "notes col-notes", title: run.notes });
  const actions = attributes(element("td", null,
    attributes(element("button", "edit"), { type: "button", class: "edit-run", "data-run": run.id, "aria-label": `edit the tags and notes of run ${run.id}` }), " ",
    attributes(element("button", "3D"), { type: "button", class: "open-3d", "data-run": run.id, "aria-label": `open run ${run.id} in the 3D view` }), " ",
    attributes(element("a", "share"), { href: `${API}/runs/${run.id}/share.html`, download: "", "aria-label": `share run ${run.id} as a standalone HTML file` }),
    ...recordingLink(run)),
  { class: "actions" });
  const row = element("tr", null, element("td", null, tick), element("td", String(run.id)), cell("kind", run.kind), statusCell(run),
    cell("ending", null, endingBadge(run.end_reason)), cell("loop", run.loop), cell("controller", run.controller ?? "—"),
    cell("target", targetText(run)), cell("controls", controlsText(run)), worldCell(run), jumpsCell(run), cell("climb", run.climb.toFixed(3)),
    cell("failure", run.failure_code ?? ""), attributes(element("td", run.tags.join(" ")), { class: "tags col-tags" }), notes,
    created(run), actions);
  row.id = `run-${run.id}`;
  return row;
}

// When a run was made and by whom (``created_by``, ``notes_by``: null for runs stored before people had names).
function created(run) {
  const moment = new Date(run.created_at);
  const by = run.created_by ? [attributes(element("small", `by ${run.created_by}`), { class: "by" })] : [];
  const notes = run.notes_by ? `; notes by ${run.notes_by}` : "";
  return attributes(cell("created", moment.toLocaleString(undefined, { dateStyle: "short", timeStyle: "short" }), ...by),
    { title: `${moment.toLocaleString()}${run.created_by ? ` by ${run.created_by}` : ""}${notes}` });
}

function recordingLink(run) {
  if (!exportsMcap(run)) return [];
  const mcap = [" ", attributes(element("a", "MCAP"), { href: `${API}/runs/${run.id}/export.mcap`, download: "", class: "export-mcap",
    "aria-label": `download run ${run.id} as an MCAP recording (Foxglove, Rerun)` })];
  if (!RECORDED_KINDS.includes(run.kind)) return mcap;
  return [...mcap, " ", attributes(element("button", "touchdowns"), { type: "button", class: "show-touchdowns", "data-run": run.id,
    "aria-label": `run ${run.id}'s touchdowns, measured and predicted` })];
}

let listing = 0;  // the newest listing asked for: an older answer arriving later is not shown
export async function loadRuns() {
  const asked = ++listing;
  formToView();
  const offset = (view.page - 1) * view.size;
  // A refused filter (a search under 3 letters) is said at its field.
  const at = { form: form(), locations: { "query.q": "q" }, action: "Filter" };
  const page = await call("GET", `/runs?limit=${view.size}&offset=${offset}&sort=${encodeURIComponent(view.sort)}&${filterQuery()}`, undefined, at);
  if (asked !== listing) return;  // the tab's first listing answered after the filter's
  if (!page.items.length && page.total > 0 && offset >= page.total) {  // past the end (fewer runs match now)
    view.page = Math.ceil(page.total / view.size);
    return loadRuns();
  }
  $("#export-csv").href = `${API}/runs/export?format=csv&${filterQuery()}`;
  $("#export-json").href = `${API}/runs/export?format=json&${filterQuery()}`;
  shownRuns.clear();
  page.items.forEach((run) => shownRuns.set(run.id, run));
  fillTable("#run-table", page.items.map(runRow), "No runs match these filters.");
  showPager(page.items.length, page.total);
  showSort();
  remember();
  if (view.by) await showAggregate(groupQuery(), view.by, view.bins);
}

function showPager(count, total) {
  const first = (view.page - 1) * view.size + 1;
  const pages = Math.max(1, Math.ceil(total / view.size));
  $("#runs-range").textContent = count
    ? `runs ${first.toLocaleString()}–${(first + count - 1).toLocaleString()} of ${total.toLocaleString()} (page ${view.page} of ${pages.toLocaleString()})`
    : "no runs match";
  $("#runs-first").disabled = $("#runs-prev").disabled = view.page <= 1;
  $("#runs-next").disabled = $("#runs-last").disabled = view.page >= pages;
  $("#run-pager").dataset.pages = String(pages);
}

function showSort() {
  for (const header of document.querySelectorAll("#run-table th[data-sort]")) {
    const name = header.dataset.sort;
    header.setAttribute("aria-sort", view.sort === name ? "ascending" : view.sort === `-${name}` ? "descending" : "none");
  }
}

// The view in the address bar and in the "Link to this view".
function remember() {
  view.basket = basketIds();
  $("#history-link").href = showView(view);
}

function again(page = 1) {
  view.page = page;
  return loadRuns();
}

on("#history-form", "submit", (event) => { event.preventDefault(); return again(); });
for (const name of ["experiment_id", "kind", "status", "end_reason", "loop", "controller", "world_id", "sort", "size"]) {
  on(`#history-form select[name=${name}]`, "change", () => again());  // a choice applies at once
}
on("#runs-first", "click", () => again(1));
on("#runs-prev", "click", () => again(Math.max(1, view.page - 1)));
on("#runs-next", "click", () => again(view.page + 1));
on("#runs-last", "click", () => again(Number($("#run-pager").dataset.pages || 1)));
on("#run-table thead", "click", (event) => {
  const button = event.target.closest("button.sort-by");
  if (!button) return;
  const name = button.dataset.sort;
  form().elements.sort.value = view.sort === `-${name}` ? name : `-${name}`;
  return again();
});

// The basket: a tick puts the run in (or takes it out); it stays there across pages and filters.
on("#run-table tbody", "change", (event) => {
  const box = event.target.closest("input[type=checkbox]");
  if (!box) return;
  const run = shownRuns.get(Number(box.value));
  if (box.checked && !addRun(run)) box.checked = false;
  if (!box.checked) removeRun(run.id);
});
onBasketChange(() => {
  for (const box of document.querySelectorAll("#run-table tbody input[type=checkbox]")) box.checked = inBasket(Number(box.value));
  if (!$("#history").hidden) remember();
});

// Columns: each can be hidden (the table's hide-NAME class), and the choice is part of the view.
function showColumns() {
  const table = $("#run-table");
  for (const name of COLUMNS) table.classList.toggle(`hide-${name}`, view.hide.includes(name));
  for (const box of document.querySelectorAll("#run-column-choices input")) box.checked = !view.hide.includes(box.name);
}
on("#run-column-choices", "change", () => {
  view.hide = [...document.querySelectorAll("#run-column-choices input")].filter((box) => !box.checked).map((box) => box.name);
  showColumns();
  remember();
});

// Experiments: a name opens its page and lists its runs; Close lists every run again.
onExperimentRuns((id) => {
  form().elements.experiment_id.value = id ?? "";
  return again();
});

// Runs grouped by a parameter, over the runs the filters select or the basket's (aggregate.js).
let groupingBasket = false;
const groupQuery = () => (groupingBasket ? basketQuery() : filterQuery());
on("#basket-group", "click", () => {
  groupingBasket = true;
  $("#aggregate-box").hidden = false;
  $("#aggregate-box").scrollIntoView({ block: "nearest" });
});
on("#group-runs", "click", () => {
  groupingBasket = false;
  $("#aggregate-box").hidden = false;
  $("#aggregate-box").scrollIntoView({ block: "nearest" });
});
on("#aggregate-form", "submit", async (event) => {
  event.preventDefault();
  view.by = $("#aggregate-by").value;
  view.bins = String(new FormData(event.target).get("bins") || "").trim();
  remember();
  await showAggregate(groupQuery(), view.by, view.bins);
});
on("#aggregate-close", "click", () => {
  view.by = view.bins = "";
  hideAggregate();
  remember();
});

// A link to a view (or a reload) shows it: History with its filters, sort, page, columns, basket.
export async function restoreView() {
  viewToForm();
  showColumns();
  if (view.by) {
    $("#aggregate-by").value = view.by;
    $("#aggregate-form").elements.bins.value = view.bins;
  }
  if (view.basket.length) restoreBasket(view.basket).catch(() => {});
  if (view.tab !== "history") return;
  selectTab("history");  // loads the experiments, then this page of runs (main.js)
  if (view.filters.experiment_id) await showExperiment(view.filters.experiment_id).catch(() => closeExperiment());
}

// Another tab: the address bar no longer names History's view (back on History, it does again).
on("nav[role=tablist]", "click", (event) => {
  const tab = event.target.closest("[role=tab]");
  if (tab && tab.dataset.tab !== "history" && location.search) history.replaceState(null, "", location.pathname);
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
  const fields = $("#run-editor-form").elements;
  const id = Number(editor.dataset.run);
  const tags = fields.tags.value.split(/[\s,]+/).filter(Boolean);
  try {
    const run = await call("PATCH", `/runs/${id}`, { tags, notes: fields.notes.value });
    shownRuns.set(run.id, run);
    refreshRun(run);
    $(`#run-${run.id}`)?.replaceWith(runRow(run));
    say(`Run ${run.id} saved.`);
  } catch (error) {
    editor.showModal();  // keep what was typed; the message above says which field to fix
    throw error;
  }
});

// "3D" on a run: replay it in the 3D view (with the basket's first other run, if any, as a ghost).
on("#run-table", "click", async (event) => {
  const button = event.target.closest("button.open-3d");
  if (!button) return;
  const runId = Number(button.dataset.run);
  const others = basketIds().filter((id) => id !== runId);
  await call("POST", "/view/replay", { viewer: VIEWER, run_id: runId, overlay_run_id: others[0] ?? null });
  selectTab("view3d");
  say(`Run ${runId} is on the 3D view's timeline${others.length ? ` with run ${others[0]} as a ghost` : ""}.`);
});
