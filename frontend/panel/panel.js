// ParkourLab control panel: plain JavaScript over the service's REST API (/api/v1).
// Every failing call shows the API's own message (for a 422: the field and the allowed range).
"use strict";

const API = "/api/v1";
const $ = (selector, root = document) => root.querySelector(selector);
const tokenInput = $("#token");
tokenInput.value = localStorage.getItem("parkourlab-token") || "";
tokenInput.addEventListener("change", () => localStorage.setItem("parkourlab-token", tokenInput.value.trim()));

function say(text, kind = "ok") {
  const box = document.createElement("div");
  box.className = `message ${kind}`;
  box.textContent = text;
  $("#messages").replaceChildren(box);
  if (kind === "ok") setTimeout(() => box.remove(), 4000);
}

function explain(body, status) {
  if (body && Array.isArray(body.detail)) {
    return body.detail.map((e) => `${(e.loc || []).filter((p) => p !== "body").join(".")}: ${e.msg}`).join("; ");
  }
  if (body && body.detail) return body.detail;
  return `HTTP ${status}`;
}

async function call(method, path, body) {
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
  if (!response.ok) {
    const message = response.status === 401 ? "Paste the API token (data/api_token) into the field at the top." : explain(data, response.status);
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
for (const tab of document.querySelectorAll("nav [role=tab]")) {
  on(tab, "click", () => {
    for (const other of document.querySelectorAll("nav [role=tab]")) other.setAttribute("aria-selected", String(other === tab));
    for (const panel of document.querySelectorAll("main [role=tabpanel]")) panel.hidden = panel.id !== tab.dataset.tab;
    if (tab.dataset.tab === "history") loadRuns();
    if (tab.dataset.tab === "jobs") loadJobs();
    if (tab.dataset.tab === "robot") refreshRobot();
    if (tab.dataset.tab === "view3d") showView();
  });
}

function selectTab(name) { $(`nav [data-tab=${name}]`).click(); }

// Simulate -----------------------------------------------------------------------------------
function simControls() {
  const form = new FormData($("#sim-form"));
  const number = (name) => Number(form.get(name));
  return {
    controls: [
      { psi0_deg: number("psiL"), zeta0: number("zetaL") },
      { psi0_deg: number("psiR"), zeta0: number("zetaR") },
    ],
    start: { xdot: number("xdot"), ydot: number("ydot") },
    jumps: number("jumps"),
  };
}

const layout = (title, x, y, extra = {}) => ({
  title: { text: title, font: { size: 14 } }, margin: { l: 55, r: 15, t: 40, b: 45 },
  xaxis: { title: { text: x } }, yaxis: { title: { text: y } }, ...extra,
});

on("#sim-form", "submit", async (event) => {
  event.preventDefault();
  const spec = simControls();
  const path = await call("POST", "/sim/trajectory", { ...spec, rate: 60 });
  const c = path.columns;
  Plotly.react("path-plot", [{ x: c.x, y: c.y, mode: "lines", name: "body" },
    { x: c.foot_x, y: c.foot_y, mode: "markers", marker: { size: 3 }, name: "foot" }],
    layout("Path between the walls", "x [l0]", "height y [l0]", { yaxis: { scaleanchor: "x", title: { text: "height y [l0]" } } }),
    { responsive: true });
  Plotly.react("height-plot", [{ x: c.time, y: c.y, mode: "lines", name: "height" }],
    layout("Height over time", "time [sqrt(l0/g)]", "y [l0]"), { responsive: true });
  const failure = path.failure ? `, failed: ${path.failure.code} at jump ${path.failure.jump}` : "";
  say(`${spec.jumps} jumps simulated${failure}.`);
});

on("#find-gait", "click", async () => {
  const spec = simControls();
  const gait = await call("POST", "/sim/fixed-point", { controls: spec.controls, guess: spec.start });
  const circle = Array.from({ length: 101 }, (_, i) => 2 * Math.PI * i / 100);
  Plotly.react("eig-plot", [
    { x: circle.map(Math.cos), y: circle.map(Math.sin), mode: "lines", name: "|λ| = 1", line: { color: "#999" } },
    { x: gait.eigenvalues.map((e) => e[0]), y: gait.eigenvalues.map((e) => e[1]), mode: "markers", name: "eigenvalues", marker: { size: 11, color: gait.stable ? "#2a9d4b" : "#d61f1f" } },
  ], layout("Eigenvalues on the unit circle", "Re λ", "Im λ", { yaxis: { scaleanchor: "x", title: { text: "Im λ" } } }), { responsive: true });
  $("#gait-readout").textContent = `Period ${gait.period} ${gait.motion} gait at (${gait.state.map((v) => v.toFixed(4)).join(", ")}): ` +
    `max |λ| = ${gait.max_abs_eigenvalue.toFixed(4)} (${gait.stable ? "stable" : "unstable"}), climb ${gait.climb_per_period.toFixed(4)} l0 per period.`;
});

// Jobs ---------------------------------------------------------------------------------------
const streams = new Map();

function jobRow(job) {
  const row = document.createElement("tr");
  row.id = `job-${job.id}`;
  const progress = `<progress max="1" value="${job.progress}" aria-label="job ${job.id} progress"></progress> ${job.completed}/${job.total}`;
  row.innerHTML = `<td>${job.id}</td><td>${job.kind}</td><td class="state">${job.state}</td><td class="progress">${progress}</td>` +
    `<td><button class="show" data-id="${job.id}">Show</button></td>` +
    `<td>${["queued", "running"].includes(job.state) ? `<button class="cancel" data-id="${job.id}">Cancel</button>` : ""}</td>`;
  return row;
}

function watch(job) {
  if (streams.has(job.id) || !["queued", "running", "cancelling"].includes(job.state)) return;
  const source = new EventSource(`${API}/jobs/${job.id}/events`);
  streams.set(job.id, source);
  source.addEventListener("progress", (event) => {
    const update = JSON.parse(event.data);
    $(`#job-${update.id}`)?.replaceWith(jobRow(update));
    if (["done", "cancelled", "failed"].includes(update.state)) {
      source.close();
      streams.delete(update.id);
      say(`Job ${update.id} ${update.state}.`, update.state === "failed" ? "error" : "ok");
    }
  });
}

async function loadJobs() {
  const page = await call("GET", "/jobs?limit=20");
  $("#job-table tbody").replaceChildren(...page.items.map(jobRow));
  page.items.forEach(watch);
}

on("#job-form", "submit", async (event) => {
  event.preventDefault();
  const form = new FormData(event.target);
  const job = await call("POST", "/jobs", {
    kind: "mjtf", psi0_deg: Number(form.get("psi0")), trials: Number(form.get("trials")), cap: Number(form.get("cap")),
    seed: Number(form.get("seed")), zeta0s: String(form.get("zeta0s")).split(",").map((v) => Number(v.trim())),
  });
  say(`Job ${job.id} scheduled: ${job.total} trials.`);
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
  if (results.levels) {
    Plotly.react("job-plot", [{
      x: results.levels.map((l) => l.zeta0), y: results.levels.map((l) => l.mean), mode: "lines+markers", name: "MJTF",
      error_y: { type: "data", array: results.levels.map((l) => l.std), visible: true },
    }], layout(`Job ${id}: Mean Jumps To Failure`, "zeta0 [l0]", "jumps to failure"), { responsive: true });
  }
});

// History ------------------------------------------------------------------------------------
function runQuery() {
  const form = new FormData($("#history-form"));
  const params = new URLSearchParams();
  for (const name of ["kind", "tag"]) if (form.get(name)) params.set(name, form.get(name));
  return params;
}

async function loadRuns() {
  const params = runQuery();
  const sort = new FormData($("#history-form")).get("sort");
  const page = await call("GET", `/runs?limit=100&sort=${sort}&${params}`);
  $("#export-csv").href = `${API}/runs/export?format=csv&${params}`;
  $("#export-json").href = `${API}/runs/export?format=json&${params}`;
  $("#run-table tbody").replaceChildren(...page.items.map((run) => {
    const row = document.createElement("tr");
    const controls = run.controls.map((c) => `${c[0]}°/${c[1]}`).join(", ");
    row.innerHTML = `<td><input type="checkbox" value="${run.id}" aria-label="select run ${run.id}"></td><td>${run.id}</td><td>${run.kind}</td>` +
      `<td>${controls}</td><td>${run.jumps_completed}/${run.jumps}</td><td>${run.climb.toFixed(3)}</td>` +
      `<td>${run.failure_code ?? ""}</td><td>${run.tags.join(" ")}</td><td>${new Date(run.created_at).toLocaleString()}</td>` +
      `<td class="actions"><button type="button" class="open-3d" data-run="${run.id}" aria-label="open run ${run.id} in the 3D view">3D</button> ` +
      `<a href="${API}/runs/${run.id}/share.html" download aria-label="share run ${run.id} as a standalone HTML file">share</a></td>`;
    return row;
  }));
}

on("#history-form", "submit", (event) => { event.preventDefault(); loadRuns(); });

// "3D" on a run: replay it in the 3D view (with the other selected run, if one, as a ghost).
on("#run-table", "click", async (event) => {
  const button = event.target.closest("button.open-3d");
  if (!button) return;
  const runId = Number(button.dataset.run);
  const others = [...document.querySelectorAll("#run-table input:checked")].map((box) => Number(box.value)).filter((id) => id !== runId);
  await call("POST", "/view/replay", { run_id: runId, overlay_run_id: others[0] ?? null });
  selectTab("view3d");
  say(`Run ${runId} is on the 3D view's timeline${others.length ? ` with run ${others[0]} as a ghost` : ""}.`);
});

on("#compare", "click", async () => {
  const ids = [...document.querySelectorAll("#run-table input:checked")].map((box) => box.value);
  if (ids.length < 2) return say("Select two or more runs to compare.", "error");
  const result = await call("GET", `/runs/compare?${ids.map((id) => `ids=${id}`).join("&")}`);
  const header = `<tr><th>field</th>${result.runs.map((r) => `<th>run ${r.id}</th>`).join("")}</tr>`;
  const rows = result.fields.filter((f) => f !== "id").map((field) =>
    `<tr class="differs"><td>${field}</td>${result.runs.map((r) => `<td>${r[field] ?? ""}</td>`).join("")}</tr>`).join("");
  $("#compare-out").innerHTML = `<table id="compare-table"><caption>What differs</caption>${header}${rows}</table>`;
});

// Robot --------------------------------------------------------------------------------------
const heights = { t: [], y: [] };
let live = null;

function showStatus(status) {
  const telemetry = status.telemetry || {};
  const tracker = status.tracker || {};
  const fields = {
    state: status.state, link: status.url || "—", battery: telemetry.battery_mv ? `${telemetry.battery_mv} mV` : "—",
    faults: telemetry.faults ?? "—", "tracker frames": tracker.received ?? "—", "tracker loss": tracker.loss !== undefined ? `${(100 * tracker.loss).toFixed(1)} %` : "—",
    run: status.run ? `${status.run.active ? "running" : status.run.end_reason}, ${status.run.touchdowns} touchdowns` : "—",
  };
  $("#robot-status").innerHTML = Object.entries(fields).map(([k, v]) => `<dt>${k}</dt><dd>${v}</dd>`).join("");
}

async function refreshRobot() { showStatus(await call("GET", "/robot")); }

function openLive() {
  if (live) return;
  live = new WebSocket(`${location.protocol === "https:" ? "wss" : "ws"}://${location.host}${API}/robot/live?rate=10`);
  live.onmessage = (event) => {
    const status = JSON.parse(event.data);
    showStatus(status);
    const pose = status.tracker && status.tracker.latest;
    if (pose) {
      heights.t.push(pose.time); heights.y.push(pose.y);
      if (heights.t.length > 600) { heights.t.shift(); heights.y.shift(); }
      // New arrays each time: Plotly.react redraws only what it sees change.
      Plotly.react("live-plot", [{ x: heights.t.slice(), y: heights.y.slice(), mode: "lines", name: "height" }],
        layout("Live height", "time [s]", "y [m]"), { responsive: true });
    }
  };
  live.onclose = () => { live = null; };
}

on("#connect-form", "submit", async (event) => {
  event.preventDefault();
  const form = new FormData(event.target);
  showStatus(await call("POST", "/robot/connect", { url: String(form.get("url")), tracker_port: Number(form.get("tracker_port")) }));
  openLive();
  say("Connected.");
});
on("#arm", "click", async () => showStatus(await call("POST", "/robot/arm")));
on("#reset", "click", async () => showStatus(await call("POST", "/robot/reset")));
on("#live-run", "click", async () => {
  showStatus(await call("POST", "/robot/runs", { controls: simControls().controls, jumps: 20 }));
  openLive();
});
on("#estop", "click", async () => {
  const result = await call("POST", "/robot/estop");
  showStatus(result);
  say(`Emergency stop acknowledged by the robot in ${result.latency_ms.toFixed(1)} ms.`);
});

// 3D view ------------------------------------------------------------------------------------
// viser serves the view on its own port of this host; the frame loads it once and keeps it.
async function showView() {
  const info = await call("GET", "/view");
  if (!info.available) {
    $("#view-status").textContent = info.reason;
    return;
  }
  const url = `${location.protocol}//${location.hostname}:${info.port}/`;
  $("#view-open").href = url;
  if ($("#view-frame").src !== url) $("#view-frame").src = url;
  $("#view-status").textContent = `Mode: ${info.mode}${info.run_id ? `, run ${info.run_id}` : ""} · ${info.updates_per_s} updates/s · the scene is shared by everyone viewing it.`;
}
