// The Jobs tab: the job form by kind, the jobs table page by page with live progress (event
// streams) and each queued job's place and estimate, results.
import { API, $, say, call, on } from "./api.js";
import { filedUnder } from "./forms.js";
import { draw, layout, plotSweep, plotBasin } from "./plots.js";
import { element, fillTable, attributes } from "./dom.js";
import { hideControlStudy, showControlStudy } from "./control_study.js";
import { hideViability, showViability } from "./viability.js";
import { hideLoopMfpt, showLoopMfpt } from "./loop_mfpt.js";
import { jobSpec } from "./job_forms.js";
import { hidePlan, showPlan } from "./plan_view.js";
import { hideWorldResults, showFootholdStudy, worldJobWords, worldMjtfWords } from "./world_results.js";
import { showReach } from "./reach_view.js";

const streams = new Map();
const FINAL = ["done", "cancelled", "failed"];

export function describeJob(job) {
  const spec = job.spec || {};
  const inWorld = worldJobWords(job);
  if (inWorld) return inWorld;
  if (job.kind === "mjtf") return `psi0 ${spec.psi0_deg}°, zeta0 ${(spec.zeta0s || []).join(", ")} × ${spec.trials} trials`;
  if (job.kind === "sweep") return `psi0 ${spec.psi0_deg}°, zeta0 ${spec.zeta0_low}–${spec.zeta0_high}, ${spec.steps} steps`;
  if (job.kind === "control-study") return `${(spec.controllers || []).join(", ")} to ${spec.target_m} m, ${spec.seeds} × ${spec.jumps} jumps`;
  if (job.kind === "mfpt") return `MFPT of ${spec.psi0_deg}°/${spec.zeta0}, grid ${spec.grid}`;
  if (job.kind === "loop-mfpt") return `MFPT of ${spec.controller} at ${spec.target_m} m, ${spec.runs} runs × ${spec.replicas} replicas`;
  if (job.kind === "viability") return `viability, ${spec.states}² states × ${spec.actions}² actions`;
  if (!spec.controls) {  // a kind without words of its own here: its numbers, as the API names them
    return Object.entries(spec).filter(([name, value]) => typeof value === "number" && name !== "version")
      .map(([name, value]) => `${name.replaceAll("_", " ")} ${value}`).join(", ");
  }
  const legs = spec.controls.map((leg) => `${leg.psi0_deg}°/${leg.zeta0}`).join(", ");
  const limit = spec.jump_limit ? `, up to ${spec.jump_limit} jumps` : "";
  return job.kind === "basin" ? `${legs}, ${spec.grid}² start states${limit}` : legs;
}

const ordinal = (n) => `${n}${[11, 12, 13].includes(n % 100) ? "th" : ({ 1: "st", 2: "nd", 3: "rd" }[n % 10] ?? "th")}`;

function duration(seconds) {
  if (seconds < 90) return `${Math.max(1, Math.round(seconds))} s`;
  if (seconds < 90 * 60) return `${Math.round(seconds / 60)} min`;
  const minutes = Math.round(seconds / 60);
  return `${Math.floor(minutes / 60)} h ${minutes % 60} min`;
}

// Where a job stands in the queue and when it should be done, as the service estimates them
// (``queue_position``: 1 = next to run, null when not queued; ``eta_s``: seconds until it should
// finish as expected on this machine, or null; ``eta_max_s``: at the latest, said where it is well
// above); "" when it gives neither (an older service does not).
export function queueWords(job) {
  const words = [];
  if (Number.isInteger(job.queue_position) && job.queue_position >= 1) {
    words.push(job.queue_position === 1 ? "next to run" : `${ordinal(job.queue_position)} in the queue`);
  }
  const seconds = (value) => typeof value === "number" && Number.isFinite(value) && value >= 0;
  if (seconds(job.eta_s)) {
    const most = seconds(job.eta_max_s) && job.eta_max_s > 1.5 * job.eta_s ? ` (at most ${duration(job.eta_max_s)})` : "";
    words.push(`done in about ${duration(job.eta_s)}${most}`);
  }
  return words.join(", ");
}

// Who submitted a job and through what (``submitted_by``: the person; ``submitted_via``: the tool's
// label), when the service says; "" for a job stored before people had names.
export function submitterWords(job) {
  if (typeof job.submitted_by !== "string" || !job.submitted_by) return "";
  const via = typeof job.submitted_via === "string" && job.submitted_via ? ` via ${job.submitted_via}` : "";
  return `${job.submitted_by}${via}`;
}

function jobRow(job) {
  const progress = attributes(element("progress", null), { max: 1, value: job.progress, "aria-label": `job ${job.id} progress` });
  const state = attributes(element("td", job.state), { class: "state" });
  if (job.error) state.title = job.error;
  const cancel = ["queued", "running"].includes(job.state) ? [attributes(element("button", "Cancel"), { class: "cancel", "data-id": job.id })] : [];
  const queue = queueWords(job);
  const row = element("tr", null,
    element("td", String(job.id)), element("td", job.kind), attributes(element("td", describeJob(job)), { class: "what" }),
    attributes(element("td", submitterWords(job)), { class: "by" }), state,
    attributes(element("td", null, progress, ` ${job.completed}/${job.total}`,
      ...(queue ? [attributes(element("small", queue), { class: "queue" })] : [])), { class: "progress" }),
    element("td", null, attributes(element("button", "Show"), { class: "show", "data-id": job.id, "data-kind": job.kind })),
    element("td", null, ...cancel));
  row.id = `job-${job.id}`;
  return row;
}

// Follow a job's event stream: its row in the Jobs table, and the callbacks of whoever asked.
export function watch(job, onFinal, onProgress) {
  if (FINAL.includes(job.state)) { if (onFinal) onFinal(job); return; }
  let entry = streams.get(job.id);
  if (!entry) {
    entry = { source: new EventSource(`${API}/jobs/${job.id}/events`), finals: [], progresses: [] };
    streams.set(job.id, entry);
    entry.source.addEventListener("progress", (event) => {
      const update = JSON.parse(event.data);
      $(`#job-${update.id}`)?.replaceWith(jobRow(update));
      entry.progresses.forEach((callback) => callback(update));
      if (FINAL.includes(update.state)) {
        entry.source.close();
        streams.delete(update.id);
        say(`Job ${update.id} ${update.state}${update.error ? `: ${update.error}` : ""}.`, update.state === "failed" ? "error" : "ok");
        entry.finals.forEach((callback) => Promise.resolve(callback(update)).catch(() => {}));
      }
    });
  }
  if (onFinal) entry.finals.push(onFinal);
  if (onProgress) entry.progresses.push(onProgress);
}

// The table shows one page of jobs, newest first; Older and Newer page through all of them. The
// API's pages are keyset pages: page k is asked with ``cursors[k]`` (null: the newest), the
// next_cursor of the page before it. ``total`` (every job) is shown when the API counts it.
const PAGE_SIZE = 20;
const paging = { cursors: [null], at: 0 };
// The page's unfinished jobs are followed by asking for the page again every REFRESH_MS while
// the tab is shown, not by an event stream each: a browser opens at most six connections to the
// service, and a page of queued jobs' streams would hold them all, every other call of the panel
// waiting behind them. Streams are kept for the jobs this panel waits on (watch: a job just
// scheduled, the Simulate tab's analyses).
const REFRESH_MS = 2000;
let refresh = null;

function followPage(jobs) {
  clearTimeout(refresh);
  const unfinished = jobs.some((job) => !FINAL.includes(job.state));
  refresh = unfinished ? setTimeout(() => { if (!$("#jobs").hidden) loadJobs().catch(() => {}); }, REFRESH_MS) : null;
}

// ``newest``: back to the first page (a job just scheduled is on it).
export async function loadJobs({ newest = false } = {}) {
  if (newest) Object.assign(paging, { cursors: [null], at: 0 });
  const cursor = paging.cursors[paging.at];
  const page = await call("GET", `/jobs?limit=${PAGE_SIZE}${cursor === null ? "" : `&cursor=${cursor}`}`);
  paging.cursors.length = paging.at + 1;
  if (page.next_cursor !== null && page.next_cursor !== undefined) paging.cursors.push(page.next_cursor);
  fillTable("#job-table", page.items.map(jobRow), paging.at ? "No older jobs." : "No jobs yet: schedule one above.");
  showPage(page.items.length, page.total);
  followPage(page.items);
}

function showPage(count, total) {
  const first = paging.at * PAGE_SIZE + 1, last = paging.at * PAGE_SIZE + count;
  const counted = Number.isInteger(total) ? ` of ${total}` : "";
  $("#jobs-range").textContent = count ? `jobs ${first}–${last}${counted}, newest first` : `no jobs here${counted ? ` (${total} in all)` : ""}`;
  $("#jobs-newer").disabled = paging.at === 0;
  $("#jobs-older").disabled = paging.cursors.length <= paging.at + 1;
}

on("#jobs-older", "click", () => {
  if (paging.cursors.length <= paging.at + 1) return;
  paging.at += 1;
  return loadJobs();
});
on("#jobs-newer", "click", () => {
  if (paging.at === 0) return;
  paging.at -= 1;
  return loadJobs();
});

on("#job-form", "submit", async (event) => {
  event.preventDefault();
  const spec = await jobSpec(event.target);
  if (!spec) return;
  const job = await call("POST", "/jobs", { ...spec.body, ...filedUnder(event.target) }, { form: event.target, locations: spec.locations });
  say(`Job ${job.id} scheduled: ${describeJob(job)}${queueWords(job) ? ` (${queueWords(job)})` : ""}.`);
  watch(job);  // its row live, and a word when it ends
  await loadJobs({ newest: true });
});

on("#job-table", "click", async (event) => {
  const id = event.target.dataset.id;
  if (!id) return;
  if (event.target.classList.contains("cancel")) {
    await call("POST", `/jobs/${id}/cancel`);
    return loadJobs();
  }
  return showJob(id);
});

// An MFPT job: the estimate in words, and each grid's MFPT against its size (the two agreeing is
// the estimate's own error).
function showMfpt(id, result) {
  const jumps = (value) => (value >= 1e5 ? value.toExponential(2) : value.toFixed(1));
  say(`Job ${id}: MFPT ${jumps(result.mfpt_jumps)} jumps (discretisation error ${(100 * result.discretisation_error).toFixed(1)}%), ` +
    `λ₂ ${result.lambda2.toFixed(6)} (1/(1−λ₂) ${jumps(result.lambda2_jumps)} jumps), ${result.cells} cells, ${result.seconds.toFixed(1)} s.`);
  draw("job-plot", [{
    x: result.grids.map((grid) => grid.cells), y: result.grids.map((grid) => grid.mfpt_jumps), mode: "lines+markers", name: "MFPT",
    text: result.grids.map((grid) => `${grid.velocity_nodes} velocity nodes, pitch spacing ${grid.pitch_spacing.toFixed(2)} σ`),
  }], layout(`Job ${id}: mean first-passage time on two grids`, "cells of the chain", "jumps to failure"));
}

// The results' plot box hidden (a job drawn without it: a stale plot of the job before would stay).
function hidePlot() {
  const box = $("#job-plot");
  if (!box.hidden && window.Plotly) Plotly.purge(box);
  box.hidden = true;
}

// A world-mjtf job: its climbs in words, and how many jumps the trials lasted.
function showWorldMjtf(id, result) {
  const summary = $("#job-summary");
  summary.textContent = worldMjtfWords(id, result);
  summary.hidden = false;
  draw("job-plot", [{ type: "histogram", x: result.jumps, name: "trials" }],
    layout(`Job ${id}: jumps each climb lasted in "${result.world}"`, "jumps", "trials"));
}

// A job's results: its plot in the Jobs tab, or a word where it has none (the table's Show, and
// an experiment's list of jobs).
export async function showJob(id) {
  const results = await call("GET", `/jobs/${id}/results`);
  const job = results.job;
  hideControlStudy();
  hideViability();
  hideLoopMfpt();
  hidePlan();
  hideWorldResults();
  if (results.levels) {
    // Only the levels with trials are drawn; a job that is not done says so in the title.
    const missing = results.missing_zeta0s || [];
    const partial = results.partial ? ` — partial (${job.state}: ${job.completed} of ${job.total} trials${
      missing.length ? `; no trials at zeta0 ${missing.join(", ")}` : ""})` : "";
    draw("job-plot", [{
      x: results.levels.map((l) => l.zeta0), y: results.levels.map((l) => l.mean), mode: "lines+markers", name: "MJTF",
      error_y: { type: "data", array: results.levels.map((l) => l.std), visible: true },
    }], layout(`Job ${id}: Mean Jumps To Failure${partial}`, "zeta0 [l0]", "jumps to failure"));
  } else if (!results.result) {
    say(`Job ${id} is ${job.state}: no result${job.error ? ` (${job.error})` : " yet"}.`, job.state === "failed" ? "error" : "ok");
  } else if (job.kind === "sweep") {
    plotSweep("job-plot", results.result, `Job ${id}: symmetric gait at psi0 = ${job.spec.psi0_deg}° over zeta0`);
  } else if (job.kind === "control-study") {
    await showControlStudy(id, results.result);
  } else if (job.kind === "basin") {
    plotBasin("job-plot", results.result, `Job ${id}: basin of attraction`);
  } else if (job.kind === "mfpt") {
    showMfpt(id, results.result);
  } else if (job.kind === "loop-mfpt") {
    showLoopMfpt(id, results.result);
  } else if (job.kind === "viability") {
    showViability(id, results.result);
  } else if (job.kind === "plan") {
    hidePlot();
    await showPlan(id, job, results.result);
  } else if (job.kind === "foothold-study") {
    hidePlot();
    showFootholdStudy(id, job, results.result);
  } else if (job.kind === "world-mjtf") {
    showWorldMjtf(id, results.result);
  } else if (job.kind === "reach") {
    showReach(id, results.result);
  } else if (job.kind !== "gaits") {
    // A kind the panel draws no plot for: its figures are in its results (GET /api/v1/jobs/{id}/results).
    say(`Job ${id} (${job.kind}) is done: its result is at ${API}/jobs/${id}/results.`);
  } else {
    const gaits = results.result.gaits || [];
    say(`Job ${id}: ${gaits.length} gait(s): ${gaits.map((g) => `period ${g.period} at (${g.state.map((v) => v.toFixed(3)).join(", ")}), max |λ| ${g.max_abs_eigenvalue.toFixed(3)}`).join("; ")}.`);
  }
}
