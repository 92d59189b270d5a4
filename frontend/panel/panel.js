// ParkourLab control panel: plain JavaScript over the service's REST API (/api/v1).
// Every failing call shows the API's own message (for a 422: the field and the allowed range).
"use strict";

const API = "/api/v1";
const $ = (selector, root = document) => root.querySelector(selector);
const TOKEN_KEY = "parkourlab-token";
const tokenInput = $("#token");
const tokenStatus = $("#token-status");

// Sign-in: `parkour serve` prints the panel's address with the token in the fragment
// (#token=…), which browsers never send to the service. Keep it and take it out of the address
// bar (and so out of the history and of what is copied from it).
const fromLink = new URLSearchParams(location.hash.slice(1)).get("token");
if (fromLink) {
  localStorage.setItem(TOKEN_KEY, fromLink.trim());
  history.replaceState(null, "", location.pathname + location.search);
}
tokenInput.value = localStorage.getItem(TOKEN_KEY) || "";
tokenInput.addEventListener("change", () => {
  localStorage.setItem(TOKEN_KEY, tokenInput.value.trim());
  checkToken();
});

// Whether the service accepts the token in the field, shown beside it (reads need none).
async function checkToken() {
  const token = tokenInput.value.trim();
  let state = "none", text = "none: you can look, not change";
  if (token) {
    try {
      const response = await fetch(`${API}/auth`, { headers: { Authorization: `Bearer ${token}` } });
      state = response.ok ? "accepted" : "refused";
      text = response.ok ? "accepted" : "not accepted: open the link parkour serve prints";
    } catch (error) {
      state = "unknown";
      text = "could not be checked: the service did not answer";
    }
  }
  tokenStatus.dataset.state = state;
  tokenStatus.textContent = text;
  tokenInput.setAttribute("aria-invalid", state === "refused" ? "true" : "false");
}
checkToken();

function say(text, kind = "ok") {
  const box = document.createElement("div");
  box.className = `message ${kind}`;
  box.textContent = text;
  $("#messages").replaceChildren(box);
  if (kind === "ok") setTimeout(() => box.remove(), 4000);
}

function explain(body, status) {
  if (body && Array.isArray(body.detail)) {
    return body.detail.map((e) => {
      const field = (e.loc || []).filter((p) => p !== "body").join(".");
      return field ? `${field}: ${e.msg}` : e.msg;
    }).join("; ");
  }
  if (body && body.detail) return body.detail;
  return `HTTP ${status}`;
}

// ``fields``: {form, locations} puts a 422's errors at their fields (Fields.markApiErrors).
async function call(method, path, body, fields) {
  const headers = { "Content-Type": "application/json" };
  const token = tokenInput.value.trim();
  if (token) headers.Authorization = `Bearer ${token}`;
  let response;
  try {
    response = await fetch(API + path, { method, headers, body: body === undefined ? undefined : JSON.stringify(body) });
  } catch (error) {
    say(`The service did not answer: ${error}`, "error");
    throw error;
  }
  const text = await response.text();
  const data = text ? JSON.parse(text) : null;
  if (!response.ok && response.status === 422 && fields && data) {
    const left = Fields.markApiErrors(fields.form, data.detail, fields.locations);
    const message = left.length ? left.join("; ") : "the service refused the marked field(s)";
    say(left.length ? `${method} ${path}: ${message}` : "Fix the marked field(s): the service refused them.", "error");
    throw new Error(message);
  }
  if (!response.ok) {
    const message = response.status === 401
      ? "This needs the API token: open the sign-in link parkour serve prints, or paste data/api_token into the field at the top."
      : explain(data, response.status);
    if (response.status === 401) checkToken();
    say(`${method} ${path}: ${message}`, "error");
    throw new Error(message);
  }
  return data;
}

// Handlers: a failed call has already told the user why (say); swallow it here so it is not
// reported again as an uncaught error.
function on(target, event, handler) {
  (typeof target === "string" ? $(target) : target).addEventListener(event, (e) => {
    Promise.resolve(handler(e)).catch(() => {});
  });
}

// Tabs ---------------------------------------------------------------------------------------
// The WAI-ARIA tabs pattern: each tab controls its panel, only the selected one is in the Tab
// order, and the arrow keys (Home, End) move between tabs.
const tabs = [...document.querySelectorAll("nav [role=tab]")];
for (const tab of tabs) {
  tab.id = `tab-${tab.dataset.tab}`;
  tab.setAttribute("aria-controls", tab.dataset.tab);
  tab.tabIndex = tab.getAttribute("aria-selected") === "true" ? 0 : -1;
  $(`#${tab.dataset.tab}`).setAttribute("aria-labelledby", tab.id);
}
on("nav[role=tablist]", "keydown", (event) => {
  const at = tabs.indexOf(document.activeElement);
  if (at < 0) return;
  const to = { ArrowRight: at + 1, ArrowLeft: at - 1, Home: 0, End: tabs.length - 1 }[event.key];
  if (to === undefined) return;
  event.preventDefault();
  const next = tabs[(to + tabs.length) % tabs.length];
  next.focus();
  next.click();
});
for (const tab of tabs) {
  on(tab, "click", () => {
    for (const other of tabs) {
      other.setAttribute("aria-selected", String(other === tab));
      other.tabIndex = other === tab ? 0 : -1;
    }
    for (const panel of document.querySelectorAll("main [role=tabpanel]")) panel.hidden = panel.id !== tab.dataset.tab;
    if (tab.dataset.tab === "history") loadExperiments().then(loadRuns).catch(() => {});
    if (tab.dataset.tab === "jobs") loadJobs();
    if (tab.dataset.tab === "robot") { refreshRobot().catch(() => {}); drawLive(); }
    syncLive();  // the live websocket is open while the Robot tab is shown
    if (tab.dataset.tab === "view3d") showView();
  });
}

function selectTab(name) { $(`nav [data-tab=${name}]`).click(); }

// The experiment a form files its run or job under (the form's "in experiment" choice), as the
// request's experiment_id; none: not filed.
function filedUnder(form) {
  const value = form.elements.experiment_id?.value;
  return value ? { experiment_id: Number(value) } : {};
}

// Simulate -----------------------------------------------------------------------------------
// Each action checks the fields it sends against the request body it sends them in (jumps: up
// to 50 for a drawn trajectory, 10,000 for a stored run), from the API's own ranges (fields.js).
const SQRT_GL0 = "√(g l0)";
const LEG_FIELDS = [
  { name: "psiL", rule: "LegIn.psi0_deg", unit: "°" }, { name: "zetaL", rule: "LegIn.zeta0", unit: "l0" },
  { name: "psiR", rule: "LegIn.psi0_deg", unit: "°" }, { name: "zetaR", rule: "LegIn.zeta0", unit: "l0" },
];
const START_FIELDS = [{ name: "xdot", rule: "StateIn.xdot", unit: SQRT_GL0 }, { name: "ydot", rule: "StateIn.ydot", unit: SQRT_GL0 }];
const SIM_LOCATIONS = {
  "controls.0.psi0_deg": "psiL", "controls.0.zeta0": "zetaL", "controls.1.psi0_deg": "psiR", "controls.1.zeta0": "zetaR",
  "start.xdot": "xdot", "start.ydot": "ydot", "guess.xdot": "xdot", "guess.ydot": "ydot", jumps: "jumps", psi0_deg: "psiL",
};
const simFields = () => ({ form: $("#sim-form"), locations: SIM_LOCATIONS });

// The checked values of ``fields`` in ``form``, or null (the bad ones are marked; the banner says so).
async function checked(form, fields) {
  const values = await Fields.readFields(form, fields);
  if (values === null) say("Fix the marked field(s) first: nothing was sent.", "error");
  else for (const banner of document.querySelectorAll("#messages .message.error")) banner.remove();
  return values;
}

// The Simulate form's legs and start (and ``jumps`` by ``jumpsRule``), or null.
async function simControls(jumpsRule) {
  const fields = [...LEG_FIELDS, ...START_FIELDS, ...(jumpsRule ? [{ name: "jumps", rule: jumpsRule, unit: "jumps" }] : [])];
  const v = await checked($("#sim-form"), fields);
  if (v === null) return null;
  return {
    controls: [{ psi0_deg: v.psiL, zeta0: v.zetaL }, { psi0_deg: v.psiR, zeta0: v.zetaR }],
    start: { xdot: v.xdot, ydot: v.ydot }, jumps: v.jumps,
  };
}

// Every plot's config: nothing leaves for Plotly's cloud (v4's "Share chart..." button is on by
// default), no Chart Studio link, no Plotly logo linking out.
const PLOT_CONFIG = Object.freeze({
  responsive: true, displaylogo: false, showLink: false, showSendToCloud: false, showEditInChartStudio: false,
  modeBarButtonsToRemove: Object.freeze(["sendChartToCloud", "sendDataToCloud", "editInChartStudio"]),
});

const layout = (title, x, y, extra = {}) => ({
  title: { text: title, font: { size: 14 } }, margin: { l: 55, r: 15, t: 40, b: 45 },
  xaxis: { title: { text: x } }, yaxis: { title: { text: y } }, ...extra,
});

on("#sim-form", "submit", async (event) => {
  event.preventDefault();
  const spec = await simControls("TrajectoryIn.jumps");
  if (!spec) return;
  const path = await call("POST", "/sim/trajectory", { ...spec, rate: 60 }, simFields());
  const c = path.columns;
  // Nondimensional, with what a unit is for the preset's robot: l0 in m, sqrt(l0/g) in s.
  const l0 = `l0 = ${path.si.l0_m.toFixed(3)} m`, unitTime = `√(l0/g) = ${path.si.time_s.toFixed(3)} s`;
  const walls = path.walls_x.map((x) => ({ type: "line", x0: x, x1: x, yref: "paper", y0: 0, y1: 1, line: { color: "#444", width: 3 } }));
  Plotly.react("path-plot", [{ x: c.x, y: c.y, mode: "lines", name: "body" },
    { x: c.foot_x, y: c.foot_y, mode: "markers", marker: { size: 3 }, name: "foot" }],
    layout("Path between the walls (grey: the walls)", `x [${l0}]`, `height y [${l0}]`,
      { yaxis: { scaleanchor: "x", title: { text: `height y [${l0}]` } }, shapes: walls }),
    PLOT_CONFIG);
  Plotly.react("height-plot", [{ x: c.time, y: c.y, mode: "lines", name: "height" }],
    layout("Height over time", `time [${unitTime}]`, `y [${l0}]`), PLOT_CONFIG);
  $("#sim-units").textContent = `Units (the ${path.si.preset} robot): length ${l0}, time ${unitTime}, ` +
    `velocity √(g l0) = ${path.si.speed_m_per_s.toFixed(3)} m/s.`;
  const failure = path.failure ? `, failed: ${path.failure.code} at jump ${path.failure.jump}` : "";
  say(`${spec.jumps} jumps simulated${failure}.`);
});

on("#save-run", "click", async () => {
  const spec = await simControls("RunCreate.jumps");
  if (!spec) return;
  const run = await call("POST", "/runs", { ...spec, trajectory_rate: 60, tags: ["panel"], ...filedUnder($("#sim-form")) }, simFields());
  say(`Run ${run.id} stored: ${run.jumps_completed}/${run.jumps} jumps, climb ${run.climb.toFixed(3)} l0. It is in History (tag "panel").`);
});

on("#find-gait", "click", async () => {
  const spec = await simControls();
  if (!spec) return;
  const gait = await call("POST", "/sim/fixed-point", { controls: spec.controls, guess: spec.start }, simFields());
  const circle = Array.from({ length: 101 }, (_, i) => 2 * Math.PI * i / 100);
  Plotly.react("eig-plot", [
    { x: circle.map(Math.cos), y: circle.map(Math.sin), mode: "lines", name: "|λ| = 1", line: { color: "#999" } },
    { x: gait.eigenvalues.map((e) => e[0]), y: gait.eigenvalues.map((e) => e[1]), mode: "markers", name: "eigenvalues", marker: { size: 11, color: gait.stable ? "#2a9d4b" : "#d61f1f" } },
  ], layout("Eigenvalues on the unit circle", "Re λ", "Im λ", { yaxis: { scaleanchor: "x", title: { text: "Im λ" } } }), PLOT_CONFIG);
  $("#gait-readout").textContent = `Period ${gait.period} ${gait.motion} gait at (${gait.state.map((v) => v.toFixed(4)).join(", ")}): ` +
    `max |λ| = ${gait.max_abs_eigenvalue.toFixed(4)} (${gait.stable ? "stable" : "unstable"}), climb ${gait.climb_per_period.toFixed(4)} l0 per period.`;
});

// Analyses: basins and sweeps are jobs (stored, with progress and cancel); the Simulate tab
// schedules small ones and draws them when done. --------------------------------------------
function plotSweep(target, result, title) {
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
  Plotly.react(target, traces, layout(title, "zeta0 [l0] (smaller: more energy)", "climb per jump [l0]", {
    yaxis2: { title: { text: "max |λ|, basin area" }, overlaying: "y", side: "right", range: [0, 1.15], dtick: 0.25, showgrid: false },
    shapes: [...inPlace, unit], legend: { orientation: "h", y: -0.32 }, margin: { l: 55, r: 55, t: 40, b: 105 },
  }), PLOT_CONFIG);
}

// Failures in the basin: one grey per kind, each named in the legend (plotly heatmaps have no
// legend entry of their own, so a marker of the same grey stands in for each).
const FAILURE_GREYS = ["#6b7280", "#c4c9d1", "#3f4650", "#9aa1ab", "#e3e6ea"];
const FAILURE_WORDS = { slip: "slips", collapse: "leg collapses", no_liftoff: "no lift-off", no_flight: "no flight", invalid_state: "invalid state" };

function plotBasin(target, result, title, start) {
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
  Plotly.react(target, traces, layout(`${title}: ${(100 * result.fraction).toFixed(1)} % converge`, "xdot at the section [sqrt(g l0)]", "ydot [sqrt(g l0)]",
    { legend: { orientation: "h", y: -0.32 }, margin: { l: 55, r: 15, t: 40, b: 105 } }), PLOT_CONFIG);
}

const jobStatus = (job) => `${job.kind} job ${job.id}: ${job.state}${job.total ? `, ${job.completed}/${job.total}` : ""}${job.error ? ` — ${job.error}` : ""}`;

// Schedule a job from the Simulate tab, show its progress there, draw its result when done.
async function analyse(spec, draw) {
  const job = await call("POST", "/jobs", { ...spec, ...filedUnder($("#sim-form")) });
  const status = $("#analysis-status");
  status.textContent = jobStatus(job);
  watch(job, async (final) => {
    status.textContent = jobStatus(final);
    if (final.state === "done") draw((await call("GET", `/jobs/${final.id}/results`)).result);
  }, (update) => { status.textContent = jobStatus(update); });
}

on("#run-basin", "click", async () => {
  const spec = await simControls();
  if (!spec) return;
  await analyse({ kind: "basin", controls: spec.controls, guess: spec.start, grid: 80, jumps: 60 },
    (result) => plotBasin("basin-plot", result, "Basin of attraction", spec.start));
});

on("#run-sweep", "click", async () => {
  const spec = await simControls();
  if (!spec) return;
  const psi0 = spec.controls[0].psi0_deg;
  await analyse({ kind: "sweep", psi0_deg: psi0, zeta0_low: 0.8, zeta0_high: 0.97, steps: 35, basin_grid: 20 },
    (result) => plotSweep("sweep-plot", result, `Symmetric gait at psi0 = ${psi0}° over zeta0`));
});

// Jobs ---------------------------------------------------------------------------------------
const streams = new Map();
const FINAL = ["done", "cancelled", "failed"];

function describeJob(job) {
  const spec = job.spec || {};
  if (job.kind === "mjtf") return `psi0 ${spec.psi0_deg}°, zeta0 ${(spec.zeta0s || []).join(", ")} × ${spec.trials} trials`;
  if (job.kind === "sweep") return `psi0 ${spec.psi0_deg}°, zeta0 ${spec.zeta0_low}–${spec.zeta0_high}, ${spec.steps} steps`;
  const legs = (spec.controls || []).map((leg) => `${leg.psi0_deg}°/${leg.zeta0}`).join(", ");
  return job.kind === "basin" ? `${legs}, ${spec.grid}² start states` : legs;
}

function jobRow(job) {
  const progress = attributes(element("progress", null), { max: 1, value: job.progress, "aria-label": `job ${job.id} progress` });
  const state = attributes(element("td", job.state), { class: "state" });
  if (job.error) state.title = job.error;
  const cancel = ["queued", "running"].includes(job.state) ? [attributes(element("button", "Cancel"), { class: "cancel", "data-id": job.id })] : [];
  const row = element("tr", null,
    element("td", String(job.id)), element("td", job.kind), attributes(element("td", describeJob(job)), { class: "what" }), state,
    attributes(element("td", null, progress, ` ${job.completed}/${job.total}`), { class: "progress" }),
    element("td", null, attributes(element("button", "Show"), { class: "show", "data-id": job.id, "data-kind": job.kind })),
    element("td", null, ...cancel));
  row.id = `job-${job.id}`;
  return row;
}

// Follow a job's event stream: its row in the Jobs table, and the callbacks of whoever asked.
function watch(job, onFinal, onProgress) {
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

async function loadJobs() {
  const page = await call("GET", "/jobs?limit=20");
  fillTable("#job-table", page.items.map(jobRow), "No jobs yet: schedule one above.");
  page.items.forEach((job) => watch(job));
}

on("#job-kind", "change", (event) => {
  for (const fieldset of document.querySelectorAll("#job-form fieldset[data-kind]")) {
    fieldset.hidden = fieldset.dataset.kind !== event.target.value;
    fieldset.disabled = fieldset.hidden;  // hidden fields are neither validated nor sent
  }
});
$("#job-kind").dispatchEvent(new Event("change"));  // also after the browser restores a form

// The job form's fields by kind: each checked against its job's request body (fields.js).
const JOB_FIELDS = {
  mjtf: [{ name: "psi0", rule: "MJTFJobCreate.psi0_deg", unit: "°" }, { name: "zeta0s", rule: "MJTFJobCreate.zeta0s", unit: "l0", list: true },
    { name: "trials", rule: "MJTFJobCreate.trials" }, { name: "cap", rule: "MJTFJobCreate.cap", unit: "jumps" }, { name: "seed", rule: "MJTFJobCreate.seed" }],
  sweep: [{ name: "sweep_psi0", rule: "SweepJobCreate.psi0_deg", unit: "°" }, { name: "zeta0_low", rule: "SweepJobCreate.zeta0_low", unit: "l0" },
    { name: "zeta0_high", rule: "SweepJobCreate.zeta0_high", unit: "l0" }, { name: "steps", rule: "SweepJobCreate.steps" },
    { name: "basin_grid", rule: "SweepJobCreate.basin_grid" }],
  basin: [{ name: "grid", rule: "BasinJobCreate.grid" }, { name: "basin_jumps", rule: "BasinJobCreate.jumps", unit: "jumps" },
    { name: "tolerance", rule: "BasinJobCreate.tolerance", unit: SQRT_GL0 }],
};
const JOB_LOCATIONS = { psi0_deg: "psi0", zeta0s: "zeta0s", trials: "trials", cap: "cap", seed: "seed", zeta0_low: "zeta0_low",
  zeta0_high: "zeta0_high", steps: "steps", basin_grid: "basin_grid", grid: "grid", jumps: "basin_jumps", tolerance: "tolerance" };

// The job to schedule from the form — {body, locations: body field -> input} — or null (a bad
// field is marked).
async function jobSpec(form) {
  const kind = form.elements.kind.value;
  const v = await checked(form, JOB_FIELDS[kind]);
  if (v === null) return null;
  if (kind === "mjtf") {
    return { body: { kind, psi0_deg: v.psi0, trials: v.trials, cap: v.cap, seed: v.seed, zeta0s: v.zeta0s }, locations: JOB_LOCATIONS };
  }
  if (kind === "sweep") {
    const body = { kind, psi0_deg: v.sweep_psi0, zeta0_low: v.zeta0_low, zeta0_high: v.zeta0_high, steps: v.steps, basin_grid: v.basin_grid };
    return { body, locations: { ...JOB_LOCATIONS, psi0_deg: "sweep_psi0" } };
  }
  const sim = await simControls();
  if (!sim) return null;
  const body = { kind, controls: sim.controls, guess: sim.start, grid: v.grid, jumps: v.basin_jumps, tolerance: v.tolerance };
  return { body, locations: JOB_LOCATIONS };
}

on("#job-form", "submit", async (event) => {
  event.preventDefault();
  const spec = await jobSpec(event.target);
  if (!spec) return;
  const job = await call("POST", "/jobs", { ...spec.body, ...filedUnder(event.target) }, { form: event.target, locations: spec.locations });
  say(`Job ${job.id} scheduled: ${describeJob(job)}.`);
  await loadJobs();
});

on("#job-table", "click", async (event) => {
  const id = event.target.dataset.id;
  if (!id) return;
  if (event.target.classList.contains("cancel")) {
    await call("POST", `/jobs/${id}/cancel`);
    return loadJobs();
  }
  const results = await call("GET", `/jobs/${id}/results`);
  const job = results.job;
  if (results.levels) {
    // Only the levels with trials are drawn; a job that is not done says so in the title.
    const missing = results.missing_zeta0s || [];
    const partial = results.partial ? ` — partial (${job.state}: ${job.completed} of ${job.total} trials${
      missing.length ? `; no trials at zeta0 ${missing.join(", ")}` : ""})` : "";
    Plotly.react("job-plot", [{
      x: results.levels.map((l) => l.zeta0), y: results.levels.map((l) => l.mean), mode: "lines+markers", name: "MJTF",
      error_y: { type: "data", array: results.levels.map((l) => l.std), visible: true },
    }], layout(`Job ${id}: Mean Jumps To Failure${partial}`, "zeta0 [l0]", "jumps to failure"), PLOT_CONFIG);
  } else if (!results.result) {
    say(`Job ${id} is ${job.state}: no result${job.error ? ` (${job.error})` : " yet"}.`, job.state === "failed" ? "error" : "ok");
  } else if (job.kind === "sweep") {
    plotSweep("job-plot", results.result, `Job ${id}: symmetric gait at psi0 = ${job.spec.psi0_deg}° over zeta0`);
  } else if (job.kind === "basin") {
    plotBasin("job-plot", results.result, `Job ${id}: basin of attraction`);
  } else {
    const gaits = results.result.gaits || [];
    say(`Job ${id}: ${gaits.length} gait(s): ${gaits.map((g) => `period ${g.period} at (${g.state.map((v) => v.toFixed(3)).join(", ")}), max |λ| ${g.max_abs_eigenvalue.toFixed(3)}`).join("; ")}.`);
  }
});

// History ------------------------------------------------------------------------------------
function runQuery() {
  const form = new FormData($("#history-form"));
  const params = new URLSearchParams();
  for (const name of ["experiment_id", "kind", "tag"]) if (form.get(name)) params.set(name, form.get(name));
  return params;
}

const shownRuns = new Map();  // id -> the run as last listed: what the editor starts from

function runRow(run) {
  const controls = run.controls.map((c) => `${c[0]}°/${c[1]}`).join(", ");
  const select = attributes(element("input", null), { type: "checkbox", value: run.id, "aria-label": `select run ${run.id}` });
  const notes = attributes(element("td", run.notes.length > 60 ? `${run.notes.slice(0, 60)}…` : run.notes), { class: "notes", title: run.notes });
  const actions = attributes(element("td", null,
    attributes(element("button", "edit"), { type: "button", class: "edit-run", "data-run": run.id, "aria-label": `edit the tags and notes of run ${run.id}` }), " ",
    attributes(element("button", "3D"), { type: "button", class: "open-3d", "data-run": run.id, "aria-label": `open run ${run.id} in the 3D view` }), " ",
    attributes(element("a", "share"), { href: `${API}/runs/${run.id}/share.html`, download: "", "aria-label": `share run ${run.id} as a standalone HTML file` })),
  { class: "actions" });
  const row = element("tr", null, element("td", null, select), element("td", String(run.id)), element("td", run.kind),
    element("td", controls), element("td", `${run.jumps_completed}/${run.jumps}`), element("td", run.climb.toFixed(3)),
    element("td", run.failure_code ?? ""), attributes(element("td", run.tags.join(" ")), { class: "tags" }), notes,
    element("td", new Date(run.created_at).toLocaleString()), actions);
  row.id = `run-${run.id}`;
  return row;
}

async function loadRuns() {
  const params = runQuery();
  const sort = new FormData($("#history-form")).get("sort");
  const page = await call("GET", `/runs?limit=100&sort=${sort}&${params}`);
  $("#export-csv").href = `${API}/runs/export?format=csv&${params}`;
  $("#export-json").href = `${API}/runs/export?format=json&${params}`;
  shownRuns.clear();
  page.items.forEach((run) => shownRuns.set(run.id, run));
  fillTable("#run-table", page.items.map(runRow), "No runs match these filters.");
}

on("#history-form", "submit", (event) => { event.preventDefault(); loadRuns(); });
on("#history-form select[name=sort]", "change", () => loadRuns());  // a new order applies at once

// Experiments group runs (and jobs) under a name; picking one filters the runs below.
async function loadExperiments() {
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

// Robot --------------------------------------------------------------------------------------
// Every status (GET /robot, each answer to a robot call, each live message) goes through
// showStatus; every value from it reaches the page as text.
const ARM_AND_LAUNCH = "The robot is disarmed. Starting the run arms it and launches it: it will jump. Continue?";
const plot = { key: undefined, label: "", t: [], y: [], lastTime: null, target: null };
let pendingTarget;  // the closed-loop target of the run this browser is starting (undefined: none)
let runWasActive = false;
let localRuns = 0;

// An element with ``text`` as its text (never parsed as markup) and ``children`` after it (nodes,
// or strings: text too). No value from the API reaches the page as markup: every row, table and
// status is built from these two.
function element(tag, text, ...children) {
  const node = document.createElement(tag);
  if (text !== null) node.textContent = text;
  node.append(...children);
  return node;
}

// A table's rows, or one row across every column saying why there are none.
function fillTable(selector, rows, emptyText) {
  const table = $(selector);
  if (!rows.length) {
    const columns = table.querySelectorAll("thead th").length || 1;
    rows = [element("tr", null, attributes(element("td", emptyText), { colspan: columns, class: "empty" }))];
  }
  table.querySelector("tbody").replaceChildren(...rows);
}

// ``node`` with these attributes, each value set as a string (an attribute value: never markup).
function attributes(node, values) {
  for (const [name, value] of Object.entries(values)) node.setAttribute(name, String(value));
  return node;
}

const definitions = (entries) => entries.flatMap(([name, value]) => [element("dt", name), element("dd", String(value))]);

function describeRun(run) {
  if (!run) return "—";
  const parts = [`${run.id !== undefined && run.id !== null ? `run ${run.id}: ` : ""}${run.active ? "running" : run.end_reason ?? "ended"}`,
    `${run.touchdowns} touchdowns`];
  if (run.jumps !== undefined) parts.push(`jumps ${run.jumps}`);  // as the service counts them
  if (typeof run.started === "number") parts.push(`started ${new Date(run.started * 1000).toLocaleTimeString()}`);
  if (run.max_seconds !== undefined) parts.push(`time limit ${run.max_seconds} s`);
  if (!run.active && run.disarm) parts.push(`disarm: ${run.disarm}`);
  if (run.stored_run_id !== undefined && run.stored_run_id !== null) parts.push(`stored as run ${run.stored_run_id}`);
  return parts.join(", ");
}

function showStatus(status) {
  if (!status || typeof status.state !== "string") return;
  const telemetry = status.telemetry || {};
  const tracker = status.tracker || {};
  const state = $("#robot-state");
  state.textContent = status.state;
  state.dataset.state = status.state;
  $("#robot-status").replaceChildren(...definitions([
    ["link", status.url || "—"],
    ["robot address", status.robot_address || "—"],
    ["battery", telemetry.battery_mv ? `${telemetry.battery_mv} mV` : "—"],
    ["faults", telemetry.faults ?? "—"],
    ["tracker frames", tracker.received ?? "—"],
    ["tracker loss", typeof tracker.loss === "number" ? `${(100 * tracker.loss).toFixed(1)} %` : "—"],
    ["run", describeRun(status.run)],
  ]));
  const counters = status.counters ? Object.entries(status.counters) : [];
  $("#robot-counters").replaceChildren(...(counters.length ? definitions(counters) : definitions([["—", "not connected"]])));
  showLatch(status);
  followRun(status);
}

// A latched e-stop: a banner on every tab until a status says it is released. An older service
// sends no ``estop``: then the state says it.
// Off the Robot tab no live messages come: while latched, a look every few seconds keeps the
// banner true (a reset from another browser takes it away).
let latchCheck = null;

function showLatch(status) {
  const estop = status.estop || { latched: status.state === "estopped", reason: null };
  $("#estop-banner").hidden = !estop.latched;
  $("#estop-reason").textContent = estop.latched && estop.reason ? `Reason: ${estop.reason}` : "";
  if (estop.latched && latchCheck === null) {
    latchCheck = setTimeout(() => {
      latchCheck = null;
      if (!liveSocket.socket && !$("#estop-banner").hidden) refreshRobot().catch(() => {});
    }, 3000);
  }
}

// The live height plot shows one run: a new run (a new id) starts it afresh. An older service
// sends neither id nor start time: a run seen becoming active is then a new one.
function followRun(status) {
  const run = status.run;
  let key = plot.key;
  let label = plot.label;
  if (run && run.id !== undefined && run.id !== null) {
    [key, label] = [`id ${run.id}`, `run ${run.id}`];
  } else if (run && typeof run.started === "number") {
    [key, label] = [`started ${run.started}`, `the run started ${new Date(run.started * 1000).toLocaleTimeString()}`];
  } else if (run && run.active && !runWasActive) {
    [key, label] = [`seen ${++localRuns}`, "this run"];
  }
  runWasActive = Boolean(run && run.active);
  const sameRun = run && typeof run.started === "number" && run.started === plot.started;  // e.g. its id just given
  if (key !== plot.key && sameRun) {
    Object.assign(plot, { key, label });
  } else if (key !== plot.key) {
    Object.assign(plot, { key, label, started: run ? run.started : undefined, t: [], y: [], lastTime: null, target: run && run.target_m != null ? run.target_m : (pendingTarget ?? null) });
    pendingTarget = undefined;
    drawLive();
  }
  const pose = status.tracker && status.tracker.latest;
  if (run && run.active && pose && pose.time !== plot.lastTime) {
    plot.lastTime = pose.time;
    plot.t.push(pose.time);
    plot.y.push(pose.y);
    if (plot.t.length > 1200) { plot.t.shift(); plot.y.shift(); }
    drawLive();
  }
}

function drawLive() {
  if ($("#robot").hidden) return;  // Plotly sizes a hidden plot wrongly; the tab redraws when shown
  const start = plot.t.length ? plot.t[0] : 0;
  const shapes = plot.target === null ? [] : [{ type: "line", xref: "paper", x0: 0, x1: 1, y0: plot.target, y1: plot.target, line: { color: "#d61f1f", dash: "dash" } }];
  const run = plot.label ? ` — ${plot.label}` : "";
  // New arrays each time: Plotly.react redraws only what it sees change.
  Plotly.react("live-plot", [{ x: plot.t.map((t) => t - start), y: plot.y.slice(), mode: "lines", name: "height" }],
    layout(`Live height${run}${plot.target === null ? "" : ` (target ${plot.target} m, dashed)`}`, "time since the run's first pose [s]", "y [m]", { shapes }),
    PLOT_CONFIG);
}

async function refreshRobot() { showStatus(await call("GET", "/robot")); }

// The live websocket: open while the Robot tab is shown and the page visible (so a second
// browser follows a run it did not start), reopened with backoff when it closes.
const liveSocket = { socket: null, retry: null, failures: 0 };

const liveWanted = () => !$("#robot").hidden && document.visibilityState === "visible";

function liveState(text) { $("#live-state").textContent = `live updates: ${text}`; }

function syncLive() {
  if (liveWanted()) openLive();
  else closeLive();
}

function openLive() {
  if (liveSocket.socket || liveSocket.retry) return;
  liveState("connecting…");
  const socket = new WebSocket(`${location.protocol === "https:" ? "wss" : "ws"}://${location.host}${API}/robot/live?rate=10`);
  liveSocket.socket = socket;
  socket.onopen = () => liveState("on");
  socket.onmessage = (event) => {
    liveSocket.failures = 0;
    showStatus(JSON.parse(event.data));
  };
  socket.onclose = () => {
    if (liveSocket.socket !== socket) return;  // closed on purpose
    liveSocket.socket = null;
    if (!liveWanted()) return liveState("off");
    const delay = Math.min(10, 0.5 * 2 ** liveSocket.failures);
    liveSocket.failures += 1;
    liveState(`lost, reconnecting in ${delay} s`);
    liveSocket.retry = setTimeout(() => { liveSocket.retry = null; if (liveWanted()) openLive(); }, delay * 1000);
  };
}

function closeLive() {
  clearTimeout(liveSocket.retry);
  liveSocket.retry = null;
  const socket = liveSocket.socket;
  liveSocket.socket = null;
  if (socket) { socket.onmessage = null; socket.close(); }
  liveState("off (Robot tab not shown)");
}

document.addEventListener("visibilitychange", syncLive);

on("#connect-form", "submit", async (event) => {
  event.preventDefault();
  const numbers = await Fields.readFields(event.target, [{ name: "tracker_port", rule: "RobotConnect.tracker_port" }]);
  if (!numbers) return;  // an empty or non-numeric port is marked at its field, never sent as 0
  const form = new FormData(event.target);
  const body = { url: String(form.get("url")).trim(), robot_address: String(form.get("robot_address")).trim(), ...numbers };
  const fields = ["url", "robot_address", "tracker_port"];
  const status = await call("POST", "/robot/connect", body, { form: event.target, locations: Object.fromEntries(fields.map((f) => [f, f])) });
  showStatus(status);
  say(`Connected to ${status.robot_address ?? body.robot_address} on ${status.url ?? body.url}.`);
});
on("#disconnect", "click", async () => { showStatus(await call("POST", "/robot/disconnect")); say("Disconnected."); });
on("#arm", "click", async () => showStatus(await call("POST", "/robot/arm")));
on("#disarm", "click", async () => showStatus(await call("POST", "/robot/disarm")));
const reset = async () => { showStatus(await call("POST", "/robot/reset")); say("E-stop reset."); };
on("#reset", "click", reset);
on("#estop-banner-reset", "click", reset);

on("#closed-loop", "change", (event) => {
  for (const name of ["target_m", "kp", "ki", "kd"]) $("#robot-run-form").elements[name].disabled = !event.target.checked;
});
$("#closed-loop").dispatchEvent(new Event("change"));

// A live run's fields, checked against the robot run's request body (fields.js); the gains only
// when the loop is closed.
const ROBOT_RUN_FIELDS = [...LEG_FIELDS, { name: "jumps", rule: "RobotRunCreate.jumps", unit: "jumps" },
  { name: "max_seconds", rule: "RobotRunCreate.max_seconds", unit: "s" }];
const CLOSED_LOOP_FIELDS = [{ name: "target_m", rule: "ClosedLoopIn.target_m", unit: "m" }, { name: "kp", rule: "ClosedLoopIn.kp" },
  { name: "ki", rule: "ClosedLoopIn.ki" }, { name: "kd", rule: "ClosedLoopIn.kd" }];
const ROBOT_RUN_LOCATIONS = { ...SIM_LOCATIONS, max_seconds: "max_seconds", "closed_loop.target_m": "target_m",
  "closed_loop.kp": "kp", "closed_loop.ki": "ki", "closed_loop.kd": "kd" };

on("#robot-run-form", "submit", async (event) => {
  event.preventDefault();
  const closed = event.target.elements.closed_loop.checked;
  const v = await checked(event.target, closed ? [...ROBOT_RUN_FIELDS, ...CLOSED_LOOP_FIELDS] : ROBOT_RUN_FIELDS);
  if (v === null) return;
  const body = { controls: [{ psi0_deg: v.psiL, zeta0: v.zetaL }, { psi0_deg: v.psiR, zeta0: v.zetaR }], jumps: v.jumps, max_seconds: v.max_seconds };
  if (closed) body.closed_loop = { target_m: v.target_m, kp: v.kp, ki: v.ki, kd: v.kd };
  Object.assign(body, filedUnder(event.target));
  // The robot's state now, not as last shown: a disarmed robot is armed by the run and jumps.
  const current = await call("GET", "/robot");
  showStatus(current);
  if (current.state === "disarmed" && !window.confirm(ARM_AND_LAUNCH)) return say("Run not started.");
  pendingTarget = body.closed_loop ? body.closed_loop.target_m : null;
  try {
    showStatus(await call("POST", "/robot/runs", body, { form: event.target, locations: ROBOT_RUN_LOCATIONS }));
  } finally {
    pendingTarget = undefined;
  }
  say(`Run started: ${body.jumps} jumps at most, ${body.max_seconds} s at most${body.closed_loop ? `, holding ${body.closed_loop.target_m} m` : ""}.`);
});
on("#stop-run", "click", async () => showStatus(await call("POST", "/robot/runs/stop")));

// The e-stop needs no token (the service allows stopping to anyone; call() sends one only when
// pasted) and always answers within 200 ms; it says whether the robot confirmed the stop.
async function emergencyStop() {
  const result = await call("POST", "/robot/estop");
  showStatus(result);
  if (result.acknowledged) {
    say(`Emergency stop acknowledged by the robot in ${Number(result.latency_ms).toFixed(1)} ms.`);
  } else if (result.state === "disconnected") {
    say(`Emergency stop NOT acknowledged: ${result.reason}. The service has no working link to the robot; without the link's heartbeats a robot disarms itself within 1 s — check the robot.`, "error");
  } else {
    say(`Emergency stop NOT acknowledged by the robot: ${result.reason}. Its heartbeats are stopped, so its watchdog disarms it within 1 s — check the robot.`, "error");
  }
}
for (const button of document.querySelectorAll("button.estop")) on(button, "click", emergencyStop);

// 3D view ------------------------------------------------------------------------------------
// viser serves the view on its own port of this host; the frame loads it once and keeps it.
// Each browser's view is its own. This page names its view with a random id, carried in the
// view's websocket path (viser's client connects to the address in its `websocket` parameter),
// so History → "3D" opens the replay here and nowhere else.
const VIEWER = Array.from(crypto.getRandomValues(new Uint8Array(12)), (byte) => byte.toString(16).padStart(2, "0")).join("");

async function showView() {
  const info = await call("GET", `/view?viewer=${VIEWER}`);
  if (!info.available) {
    $("#view-status").textContent = info.reason;
    if (info.starting) setTimeout(showView, 1000); // built in the background at start-up
    return;
  }
  const page = `${location.protocol}//${location.hostname}:${info.port}/`;
  const socket = `${location.protocol === "https:" ? "wss:" : "ws:"}//${location.hostname}:${info.port}/viewer/${VIEWER}`;
  $("#view-open").href = page; // a window of its own is a view of its own
  const frame = $("#view-frame");
  if (frame.dataset.viewer !== VIEWER) {
    frame.dataset.viewer = VIEWER;
    frame.src = `${page}?websocket=${socket}`;
  }
  const showing = info.mode ? `Mode: ${info.mode}${info.run_id ? `, run ${info.run_id}` : ""}` : "Connecting…";
  $("#view-status").textContent = `${showing} · ${info.updates_per_s} updates/s · this view is yours: what you do in it shows in your browser only.`;
}
