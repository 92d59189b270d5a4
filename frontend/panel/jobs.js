// The Jobs tab: the job form by kind, the jobs table page by page with live progress (event
// streams) and each queued job's place and estimate, results.
import { API, $, say, call, on } from "./api.js";
import { filedUnder, SQRT_GL0, checked, simControls } from "./forms.js";
import { draw, layout, plotSweep, plotBasin } from "./plots.js";
import { element, fillTable, attributes } from "./dom.js";
import { hideControlStudy, showControlStudy } from "./control_study.js";
import { hideViability, showViability } from "./viability.js";
import { hideLoopMfpt, showLoopMfpt } from "./loop_mfpt.js";
import { loadCatalog } from "./catalog.js";
import { generatedBody, generatedFieldset } from "./job_forms.js";

const streams = new Map();
const FINAL = ["done", "cancelled", "failed"];

export function describeJob(job) {
  const spec = job.spec || {};
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
// finish, or null); "" when it gives neither (an older service does not).
export function queueWords(job) {
  const words = [];
  if (Number.isInteger(job.queue_position) && job.queue_position >= 1) {
    words.push(job.queue_position === 1 ? "next to run" : `${ordinal(job.queue_position)} in the queue`);
  }
  if (typeof job.eta_s === "number" && Number.isFinite(job.eta_s) && job.eta_s >= 0) words.push(`done in about ${duration(job.eta_s)}`);
  return words.join(", ");
}

function jobRow(job) {
  const progress = attributes(element("progress", null), { max: 1, value: job.progress, "aria-label": `job ${job.id} progress` });
  const state = attributes(element("td", job.state), { class: "state" });
  if (job.error) state.title = job.error;
  const cancel = ["queued", "running"].includes(job.state) ? [attributes(element("button", "Cancel"), { class: "cancel", "data-id": job.id })] : [];
  const queue = queueWords(job);
  const row = element("tr", null,
    element("td", String(job.id)), element("td", job.kind), attributes(element("td", describeJob(job)), { class: "what" }), state,
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

on("#job-kind", "change", (event) => {
  for (const fieldset of document.querySelectorAll("#job-form fieldset[data-kind]")) {
    fieldset.hidden = fieldset.dataset.kind !== event.target.value;
    fieldset.disabled = fieldset.hidden;  // hidden fields are neither validated nor sent
  }
});

// The kind chooser, from the service's catalog: a kind with its own fieldset in index.html, or
// one built from its request's schema (job_forms.js), in the registry's order; a kind whose
// body the panel cannot build (a gait search's legs) is left to the API.
const GENERATED = new Map();  // kind -> its generated form's fields
async function fillJobKinds() {
  const form = $("#job-form"), select = $("#job-kind");
  const options = [];
  for (const kind of (await loadCatalog()).job_kinds) {
    if (!form.querySelector(`fieldset[data-kind="${kind.name}"]`)) {
      const made = await generatedFieldset(kind);
      if (!made) continue;
      GENERATED.set(kind.name, made.fields);
      form.querySelector(":scope > .buttons").before(made.fieldset);
    }
    options.push(attributes(element("option", kind.title), { value: kind.name }));
  }
  const chosen = select.value;
  select.replaceChildren(...options);
  if (options.some((option) => option.value === chosen)) select.value = chosen;
  select.dispatchEvent(new Event("change"));  // its kind's fields shown (also after the browser restores a form)
}
fillJobKinds().catch(() => {});

// The job form's fields by kind: each checked against its job's request body (fields.js).
const JOB_FIELDS = {
  mjtf: [{ name: "psi0", rule: "MJTFJobCreate.psi0_deg", unit: "°" }, { name: "zeta0s", rule: "MJTFJobCreate.zeta0s", unit: "l0", list: true },
    { name: "trials", rule: "MJTFJobCreate.trials" }, { name: "cap", rule: "MJTFJobCreate.cap", unit: "jumps" }, { name: "seed", rule: "MJTFJobCreate.seed" }],
  sweep: [{ name: "sweep_psi0", rule: "SweepJobCreate.psi0_deg", unit: "°" }, { name: "zeta0_low", rule: "SweepJobCreate.zeta0_low", unit: "l0" },
    { name: "zeta0_high", rule: "SweepJobCreate.zeta0_high", unit: "l0" }, { name: "steps", rule: "SweepJobCreate.steps" },
    { name: "basin_grid", rule: "SweepJobCreate.basin_grid" }],
  basin: [{ name: "grid", rule: "BasinJobCreate.grid" }, { name: "basin_jumps", rule: "BasinJobCreate.jumps", unit: "jumps" },
    { name: "jump_limit", rule: "BasinJobCreate.jump_limit", unit: "jumps", optional: true }, { name: "tolerance", rule: "BasinJobCreate.tolerance", unit: SQRT_GL0 }],
  "control-study": [{ name: "study_target", rule: "ControlStudyJobCreate.target_m", unit: "m" }, { name: "study_seeds", rule: "ControlStudyJobCreate.seeds" },
    { name: "study_jumps", rule: "ControlStudyJobCreate.jumps", unit: "jumps" }, { name: "study_seed0", rule: "ControlStudyJobCreate.seed0" }],
  mfpt: [{ name: "mfpt_psi0", rule: "MfptJobCreate.psi0_deg", unit: "°" }, { name: "mfpt_zeta0", rule: "MfptJobCreate.zeta0", unit: "l0" },
    { name: "mfpt_velocity", rule: "NoiseIn.velocity", unit: SQRT_GL0 }, { name: "mfpt_drift", rule: "NoiseIn.pitch_drift_deg", unit: "°" },
    { name: "mfpt_grid", rule: "MfptJobCreate.grid" }, { name: "mfpt_pitch", rule: "MfptJobCreate.pitch_spacing", unit: "σ" }],
  "loop-mfpt": [{ name: "loop_target", rule: "LoopMfptJobCreate.target_m", unit: "m" }, { name: "loop_velocity", rule: "LoopNoiseIn.velocity", unit: SQRT_GL0 },
    { name: "loop_runs", rule: "LoopMfptJobCreate.runs" }, { name: "loop_replicas", rule: "LoopMfptJobCreate.replicas" }, { name: "loop_seed", rule: "LoopMfptJobCreate.seed" }],
  viability: [{ name: "viability_states", rule: "ViabilityJobCreate.states" }, { name: "viability_actions", rule: "ViabilityJobCreate.actions" },
    { name: "viability_psi0_low", rule: "ViabilityJobCreate.psi0_low_deg", unit: "°" }, { name: "viability_psi0_high", rule: "ViabilityJobCreate.psi0_high_deg", unit: "°" },
    { name: "viability_zeta0_low", rule: "ViabilityJobCreate.zeta0_low", unit: "l0" }, { name: "viability_zeta0_high", rule: "ViabilityJobCreate.zeta0_high", unit: "l0" }],
};
const MFPT_LOCATIONS = { psi0_deg: "mfpt_psi0", zeta0: "mfpt_zeta0", grid: "mfpt_grid", pitch_spacing: "mfpt_pitch",
  "noise.velocity": "mfpt_velocity", "noise.pitch_drift_deg": "mfpt_drift" };
const LOOP_FIELDS = { controller: "loop_controller", target_m: "loop_target", "noise.velocity": "loop_velocity", runs: "loop_runs",
  replicas: "loop_replicas", seed: "loop_seed" };
// Under its kind too (the API's 422 names it first); the rule across fields (replicas × runs) is marked at replicas.
const LOOP_LOCATIONS = { ...LOOP_FIELDS, ...Object.fromEntries(Object.entries(LOOP_FIELDS).map(([field, input]) => [`loop-mfpt.${field}`, input])),
  "loop-mfpt": "loop_replicas" };
const VIABILITY_LOCATIONS = { states: "viability_states", actions: "viability_actions", psi0_low_deg: "viability_psi0_low",
  psi0_high_deg: "viability_psi0_high", zeta0_low: "viability_zeta0_low", zeta0_high: "viability_zeta0_high" };
const STUDY_LOCATIONS = { controllers: "study_controllers", target_m: "study_target", seeds: "study_seeds", jumps: "study_jumps",
  seed0: "study_seed0" };
const JOB_LOCATIONS = { psi0_deg: "psi0", zeta0s: "zeta0s", trials: "trials", cap: "cap", seed: "seed", zeta0_low: "zeta0_low",
  zeta0_high: "zeta0_high", steps: "steps", basin_grid: "basin_grid", grid: "grid", jumps: "basin_jumps", jump_limit: "jump_limit", tolerance: "tolerance" };

// The job to schedule from the form — {body, locations: body field -> input} — or null (a bad
// field is marked).
async function jobSpec(form) {
  const kind = form.elements.kind.value;
  const v = await checked(form, JOB_FIELDS[kind] ?? GENERATED.get(kind));
  if (v === null) return null;
  if (GENERATED.has(kind)) return generatedBody(kind, GENERATED.get(kind), v);
  if (kind === "mjtf") {
    return { body: { kind, psi0_deg: v.psi0, trials: v.trials, cap: v.cap, seed: v.seed, zeta0s: v.zeta0s }, locations: JOB_LOCATIONS };
  }
  if (kind === "control-study") {
    const controllers = [...form.elements.study_controllers.selectedOptions].map((option) => option.value);
    const body = { kind, controllers, target_m: v.study_target, seeds: v.study_seeds, jumps: v.study_jumps, seed0: v.study_seed0 };
    return { body, locations: { ...STUDY_LOCATIONS, ...Object.fromEntries(Object.entries(STUDY_LOCATIONS).map(([field, input]) => [`control-study.${field}`, input])) } };
  }
  if (kind === "mfpt") {
    const body = { kind, psi0_deg: v.mfpt_psi0, zeta0: v.mfpt_zeta0, grid: v.mfpt_grid, pitch_spacing: v.mfpt_pitch,
      noise: { velocity: v.mfpt_velocity, pitch_drift_deg: v.mfpt_drift } };
    return { body, locations: MFPT_LOCATIONS };
  }
  if (kind === "loop-mfpt") {
    const body = { kind, controller: form.elements.loop_controller.value, target_m: v.loop_target, noise: { velocity: v.loop_velocity, pitch_drift_deg: 0 },
      runs: v.loop_runs, replicas: v.loop_replicas, seed: v.loop_seed };
    return { body, locations: LOOP_LOCATIONS };
  }
  if (kind === "viability") {
    const body = { kind, states: v.viability_states, actions: v.viability_actions, psi0_low_deg: v.viability_psi0_low,
      psi0_high_deg: v.viability_psi0_high, zeta0_low: v.viability_zeta0_low, zeta0_high: v.viability_zeta0_high };
    return { body, locations: VIABILITY_LOCATIONS };
  }
  if (kind === "sweep") {
    const body = { kind, psi0_deg: v.sweep_psi0, zeta0_low: v.zeta0_low, zeta0_high: v.zeta0_high, steps: v.steps, basin_grid: v.basin_grid };
    return { body, locations: { ...JOB_LOCATIONS, psi0_deg: "sweep_psi0" } };
  }
  const sim = await simControls();
  if (!sim) return null;
  const body = { kind, controls: sim.controls, guess: sim.start, grid: v.grid, jumps: v.basin_jumps, jump_limit: v.jump_limit, tolerance: v.tolerance };
  return { body, locations: JOB_LOCATIONS };
}

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

// A job's results: its plot in the Jobs tab, or a word where it has none (the table's Show, and
// an experiment's list of jobs).
export async function showJob(id) {
  const results = await call("GET", `/jobs/${id}/results`);
  const job = results.job;
  hideControlStudy();
  hideViability();
  hideLoopMfpt();
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
  } else if (job.kind !== "gaits") {
    // A kind the panel draws no plot for: its figures are in its results (GET /api/v1/jobs/{id}/results).
    say(`Job ${id} (${job.kind}) is done: its result is at ${API}/jobs/${id}/results.`);
  } else {
    const gaits = results.result.gaits || [];
    say(`Job ${id}: ${gaits.length} gait(s): ${gaits.map((g) => `period ${g.period} at (${g.state.map((v) => v.toFixed(3)).join(", ")}), max |λ| ${g.max_abs_eigenvalue.toFixed(3)}`).join("; ")}.`);
  }
}
