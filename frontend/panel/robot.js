// The Robot tab: connect, arm, live runs (open and closed loop) and who runs one, the live plot
// and websocket, the emergency stop (no token needed). The latched e-stop's banner: events.js.
import { API, $, say, call, on } from "./api.js";
import { onRobotEvent, statusSeen } from "./events.js";
import { filedUnder, LEG_FIELDS, SIM_LOCATIONS, checked } from "./forms.js";
import { draw, layout } from "./plots.js";
import { definitions } from "./dom.js";
import { followJournal, following, planRunBody } from "./robot_plan.js";
import { cachedWorld } from "./world_list.js";

// Every status (GET /robot, each answer to a robot call, each live message) goes through
// showStatus; every value from it reaches the page as text.
const ARM_AND_LAUNCH = "The robot is disarmed. Starting the run arms it and launches it: it will jump. Continue?";
export const plot = { key: undefined, label: "", t: [], y: [], lastTime: null, target: null };
let pendingTarget;  // the closed-loop target of the run this browser is starting (undefined: none)
let runWasActive = false;
let localRuns = 0;

const clock = (epochSeconds) => new Date(epochSeconds * 1000).toLocaleTimeString();
// Who started a run, when the service says (``started_by``: absent from an older one, or null).
const startedBy = (run) => (typeof run.started_by === "string" && run.started_by ? ` by ${run.started_by}` : "");

// How long ago the tracker's last pose of the robot arrived: a silent tracker shows at once.
const lastPose = (ms) => (ms < 1000 ? `${Math.round(ms)} ms ago` : `${(ms / 1000).toFixed(1)} s ago (tracker silent)`);

// The "run" entry of the status: its id (the entry's name says "run" already), how it stands, …
function describeRun(run) {
  if (!run) return "—";
  const parts = [`${run.id !== undefined && run.id !== null ? `${run.id}: ` : ""}${run.active ? "running" : run.end_reason ?? "ended"}`,
    `${run.touchdowns} touchdown${run.touchdowns === 1 ? "" : "s"}`];
  if (run.jumps !== undefined) parts.push(`jumps ${run.jumps}`);  // as the service counts them
  if (typeof run.started === "number") parts.push(`started ${clock(run.started)}${startedBy(run)}`);
  if (run.max_seconds !== undefined) parts.push(`time limit ${run.max_seconds} s`);
  if (run.world_id != null) parts.push(`in world ${run.world_id}${cachedWorld(run.world_id) ? ` "${cachedWorld(run.world_id).name}"` : ""}`);
  if (run.plan_job_id != null) parts.push(`following plan job ${run.plan_job_id}`);
  if (run.tracker_gaps) parts.push(`tracker gaps: ${run.tracker_gaps} (longest ${Math.round(run.longest_tracker_gap_ms)} ms)`);
  if (!run.active && Array.isArray(run.robot_faults) && run.robot_faults.length) parts.push(`robot faults: ${run.robot_faults.join(", ")}`);
  if (!run.active && run.disarm) parts.push(`disarm: ${run.disarm}`);
  if (run.stored_run_id !== undefined && run.stored_run_id !== null) parts.push(`stored as run ${run.stored_run_id}`);
  return parts.join(", ");
}

export function showStatus(status) {
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
    ["last pose", typeof tracker.last_pose_age_ms === "number" ? lastPose(tracker.last_pose_age_ms) : "—"],
    ["run", describeRun(status.run)],
  ]));
  const counters = status.counters ? Object.entries(status.counters) : [];
  $("#robot-counters").replaceChildren(...(counters.length ? definitions(counters) : definitions([["—", "not connected"]])));
  statusSeen(status);  // the e-stop banner
  showRunOwner(status.run);
  followRun(status);
  followJournal(status.run);
}

// Who runs the robot: while a live run goes, which run, since when and who started it, with its
// Stop (on the Robot tab; the run's summary comes with every status and every robot event).
function showRunOwner(run) {
  const box = $("#run-owner");
  box.hidden = !(run && run.active);
  if (box.hidden) return;
  const name = run.id !== undefined && run.id !== null ? `Live run ${run.id}` : "A live run";
  const since = typeof run.started === "number" ? ` since ${clock(run.started)}` : "";
  const who = startedBy(run);
  $("#run-owner-text").textContent = `${name} is running${since}${who ? `, started${who}` : ""}.`;
}
onRobotEvent((summary) => showRunOwner(summary.run));

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
    drawLive(true);
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

// The live plot is redrawn at most every LIVE_PLOT_MS, however fast statuses come: one Plotly
// redraw lays the whole figure out again (axes, ticks), and at the live socket's 10 a second it
// took all of a slow machine's main thread, so the page answered clicks seconds late.
const LIVE_PLOT_MS = 500;
const livePlotDrawn = { at: -Infinity, pending: null };

// ``now``: draw at once (a new run's empty plot, a tab just shown), not at the next turn.
export function drawLive(now = false) {
  if (now) {
    clearTimeout(livePlotDrawn.pending);
    livePlotDrawn.pending = null;
  } else if (livePlotDrawn.pending !== null) {
    return;  // already due: it draws the newest data then
  }
  const wait = now ? 0 : livePlotDrawn.at + LIVE_PLOT_MS - performance.now();
  if (wait > 0) {
    livePlotDrawn.pending = setTimeout(() => { livePlotDrawn.pending = null; drawLive(); }, wait);
    return;
  }
  livePlotDrawn.at = performance.now();
  if ($("#robot").hidden) return;  // Plotly sizes a hidden plot wrongly; the tab redraws when shown
  if (!plot.t.length && $("#live-plot").hidden) return;  // nothing drawn yet: the box stays hidden until a pose comes
  const start = plot.t.length ? plot.t[0] : 0;
  const shapes = plot.target === null ? [] : [{ type: "line", xref: "paper", x0: 0, x1: 1, y0: plot.target, y1: plot.target, line: { color: "#d61f1f", dash: "dash" } }];
  const run = plot.label ? ` — ${plot.label}` : "";
  // New arrays each time: Plotly.react redraws only what it sees change.
  draw("live-plot", [{ x: plot.t.map((t) => t - start), y: plot.y.slice(), mode: "lines", name: "height" }],
    layout(`Live height${run}${plot.target === null ? "" : ` (target ${plot.target} m, dashed)`}`, "time since the run's first pose [s]", "y [m]", { shapes }));
}

export async function refreshRobot() { showStatus(await call("GET", "/robot")); }

// The live websocket: open while the Robot tab is shown and the page visible (so a second
// browser follows a run it did not start), reopened with backoff when it closes.
const liveSocket = { socket: null, retry: null, failures: 0 };

const liveWanted = () => !$("#robot").hidden && document.visibilityState === "visible";

function liveState(text) { $("#live-state").textContent = `live updates: ${text}`; }

export function syncLive() {
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

export function closeLive() {
  clearTimeout(liveSocket.retry);
  liveSocket.retry = null;
  const socket = liveSocket.socket;
  liveSocket.socket = null;
  if (socket) { socket.onmessage = null; socket.close(); }
  liveState("off (Robot tab not shown)");
}

document.addEventListener("visibilitychange", syncLive);

// The connect form (the link, the tracker and its protocol): connect.js.
on("#disconnect", "click", async () => { showStatus(await call("POST", "/robot/disconnect")); say("Disconnected."); });
on("#arm", "click", async () => showStatus(await call("POST", "/robot/arm")));
on("#disarm", "click", async () => showStatus(await call("POST", "/robot/disarm")));
const reset = async () => { showStatus(await call("POST", "/robot/reset")); say("E-stop reset."); };
on("#reset", "click", reset);
on("#estop-banner-reset", "click", reset);

on("#closed-loop", "change", (event) => {
  for (const name of ["controller", "target_m", "kp", "ki", "kd"]) $("#robot-run-form").elements[name].disabled = !event.target.checked;
});
$("#closed-loop").dispatchEvent(new Event("change"));

// A live run's fields, checked against the robot run's request body (fields.js); the gains only
// when the loop is closed.
const ROBOT_RUN_FIELDS = [...LEG_FIELDS, { name: "jumps", rule: "RobotRunCreate.jumps", unit: "jumps" },
  { name: "max_seconds", rule: "RobotRunCreate.max_seconds", unit: "s" },
  { name: "tracker_timeout_ms", rule: "RobotRunCreate.tracker_timeout_ms", unit: "ms" }];
const CLOSED_LOOP_FIELDS = [{ name: "target_m", rule: "ClosedLoopIn.target_m", unit: "m" }, { name: "kp", rule: "ClosedLoopIn.kp" },
  { name: "ki", rule: "ClosedLoopIn.ki" }, { name: "kd", rule: "ClosedLoopIn.kd" }];
const ROBOT_RUN_LOCATIONS = { ...SIM_LOCATIONS, max_seconds: "max_seconds", tracker_timeout_ms: "tracker_timeout_ms", "closed_loop.target_m": "target_m",
  "closed_loop.kp": "kp", "closed_loop.ki": "ki", "closed_loop.kd": "kd", "closed_loop.controller": "controller", plan_job_id: "plan_job_id" };
const RUN_LIMIT_FIELDS = ROBOT_RUN_FIELDS.filter((field) => !LEG_FIELDS.includes(field));

on("#robot-run-form", "submit", async (event) => {
  event.preventDefault();
  const closed = event.target.elements.closed_loop.checked, plan = following();
  const v = await checked(event.target, plan ? RUN_LIMIT_FIELDS : closed ? [...ROBOT_RUN_FIELDS, ...CLOSED_LOOP_FIELDS] : ROBOT_RUN_FIELDS);
  if (v === null) return;
  const body = plan ? planRunBody(v) : { controls: [{ psi0_deg: v.psiL, zeta0: v.zetaL }, { psi0_deg: v.psiR, zeta0: v.zetaR }], jumps: v.jumps,
    max_seconds: v.max_seconds, tracker_timeout_ms: v.tracker_timeout_ms };
  if (closed && !plan) body.closed_loop = { controller: event.target.elements.controller.value, target_m: v.target_m, kp: v.kp, ki: v.ki, kd: v.kd };
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
  const law = body.closed_loop ? `, ${body.closed_loop.controller} holding ${body.closed_loop.target_m} m` : body.plan_job_id ? `, following plan job ${body.plan_job_id}` : "";
  say(`Run started: ${body.jumps} jumps at most, ${body.max_seconds} s at most${law}.`);
});
const stopRun = async () => showStatus(await call("POST", "/robot/runs/stop"));
on("#stop-run", "click", stopRun);
on("#run-owner-stop", "click", stopRun);

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
