// The Simulate tab: a trajectory, a stored run, the fixed point, and quick basin and sweep jobs.
import { $, say, call, on } from "./api.js";
import { Fields } from "./fields.js";
import { filedUnder, simFields, simControls, simControlsWith, SIM_LOCATIONS } from "./forms.js";
import { draw, layout, plotSweep, plotBasin } from "./plots.js";
import { queueWords, watch } from "./jobs.js";

// A saved run keeps its path at the rate the trajectory is drawn, or fewer samples where the
// service's bound on a stored path (rate × jumps, RunCreate's "x-max-rate-times-jumps") asks for
// it: a long run's path is thinned, and below MIN_PATH_RATE it is left out (the 3D view then
// simulates the run again to replay it).
const PATH_RATE = 60;  // samples per √(l0/g)
const MIN_PATH_RATE = 5;  // about 8 samples a jump: coarser is no path worth keeping

on("#sim-form", "submit", async (event) => {
  event.preventDefault();
  const spec = await simControls("TrajectoryIn.jumps");
  if (!spec) return;
  const path = await call("POST", "/sim/trajectory", { ...spec, rate: PATH_RATE }, simFields("Run trajectory"));
  const c = path.columns;
  // Nondimensional, with what a unit is for the preset's robot: l0 in m, sqrt(l0/g) in s.
  const l0 = `l0 = ${path.si.l0_m.toFixed(3)} m`, unitTime = `√(l0/g) = ${path.si.time_s.toFixed(3)} s`;
  const walls = path.walls_x.map((x) => ({ type: "line", x0: x, x1: x, yref: "paper", y0: 0, y1: 1, line: { color: "#444", width: 3 } }));
  draw("path-plot", [{ x: c.x, y: c.y, mode: "lines", name: "body" },
    { x: c.foot_x, y: c.foot_y, mode: "markers", marker: { size: 3 }, name: "foot" }],
    layout("Path between the walls (grey: the walls)", `x [${l0}]`, `height y [${l0}]`,
      { yaxis: { scaleanchor: "x", title: { text: `height y [${l0}]` } }, shapes: walls }));
  draw("height-plot", [{ x: c.time, y: c.y, mode: "lines", name: "height" }],
    layout("Height over time", `time [${unitTime}]`, `y [${l0}]`));
  $("#sim-units").textContent = `Units (the ${path.si.preset} robot): length ${l0}, time ${unitTime}, ` +
    `velocity √(g l0) = ${path.si.speed_m_per_s.toFixed(3)} m/s.`;
  const failure = path.failure ? `, failed: ${path.failure.code} at jump ${path.failure.jump}` : "";
  say(`${spec.jumps} jumps simulated${failure}.`);
});

async function pathRate(jumps) {
  const bound = await Fields.annotation("RunCreate.trajectory_rate", "x-max-rate-times-jumps");
  const rate = bound === undefined ? PATH_RATE : Math.min(PATH_RATE, Math.floor(bound / jumps));
  if (rate >= PATH_RATE) return { rate, note: "" };
  const why = `a stored path is held to rate × jumps ≤ ${bound.toLocaleString("en")}`;
  if (rate < MIN_PATH_RATE) return { rate: null, note: `, without its path (${jumps} jumps would leave under ${MIN_PATH_RATE} samples per √(l0/g): ${why})` };
  return { rate, note: `, its path thinned to ${rate} samples per √(l0/g) (from ${PATH_RATE}: ${why})` };
}

on("#save-run", "click", async () => {
  const spec = await simControls("RunCreate.jumps");
  if (!spec) return;
  const { rate, note } = await pathRate(spec.jumps);
  const world = $("#sim-world").value ? { world_id: Number($("#sim-world").value) } : {};  // none: parallel walls
  const body = { ...spec, trajectory_rate: rate, tags: ["panel"], ...filedUnder($("#sim-form")), ...world };
  const run = await call("POST", "/runs", body, simFields("Save run"));
  const where = run.world_id ? ` in world #${run.world_id}` : "";
  say(`Run ${run.id} stored${where}: ${run.jumps_completed}/${run.jumps} jumps, climb ${run.climb.toFixed(3)} l0${note}. It is in History (tag "panel").`);
});

on("#find-gait", "click", async () => {
  const spec = await simControls();
  if (!spec) return;
  const gait = await call("POST", "/sim/fixed-point", { controls: spec.controls, guess: spec.start }, simFields("Fixed point"));
  const circle = Array.from({ length: 101 }, (_, i) => 2 * Math.PI * i / 100);
  draw("eig-plot", [
    { x: circle.map(Math.cos), y: circle.map(Math.sin), mode: "lines", name: "|λ| = 1", line: { color: "#999" } },
    { x: gait.eigenvalues.map((e) => e[0]), y: gait.eigenvalues.map((e) => e[1]), mode: "markers", name: "eigenvalues", marker: { size: 11, color: gait.stable ? "#2a9d4b" : "#d61f1f" } },
  ], layout("Eigenvalues on the unit circle", "Re λ", "Im λ", { yaxis: { scaleanchor: "x", title: { text: "Im λ" } } }));
  $("#gait-readout").textContent = `Period ${gait.period} ${gait.motion} gait at (${gait.state.map((v) => v.toFixed(4)).join(", ")}): ` +
    `max |λ| = ${gait.max_abs_eigenvalue.toFixed(4)} (${gait.stable ? "stable" : "unstable"}), climb ${gait.climb_per_period.toFixed(4)} l0 per period.`;
});


const jobStatus = (job) => `${job.kind} job ${job.id}: ${job.state}${queueWords(job) ? ` (${queueWords(job)})` : ""}` +
  `${job.total ? `, ${job.completed}/${job.total}` : ""}${job.error ? ` — ${job.error}` : ""}`;

// Schedule a job from the Simulate tab, show its progress there, draw its result when done.
// ``fields``: where a 422 is marked (api.js call), if the job takes a field of the form.
async function analyse(spec, draw, fields) {
  const job = await call("POST", "/jobs", { ...spec, ...filedUnder($("#sim-form")) }, fields);
  const status = $("#analysis-status");
  status.textContent = jobStatus(job);
  watch(job, async (final) => {
    status.textContent = jobStatus(final);
    if (final.state === "done") draw((await call("GET", `/jobs/${final.id}/results`)).result);
  }, (update) => { status.textContent = jobStatus(update); });
}

// The basin's jump limit: empty, none (the cells undecided at the first cap stay undecided).
const BASIN_LIMIT = { name: "basin_jump_limit", rule: "BasinJobCreate.jump_limit", unit: "jumps", optional: true };

on("#run-basin", "click", async () => {
  const checkedFields = await simControlsWith([BASIN_LIMIT]);
  if (!checkedFields) return;
  const { spec, values } = checkedFields;
  // A rule across the job's fields (the limit below the first cap, the work budget) comes back at
  // "basin": here, with the grid and the first cap fixed, only the limit can break it.
  const locations = { ...SIM_LOCATIONS, jump_limit: BASIN_LIMIT.name, basin: BASIN_LIMIT.name };
  const fields = { ...simFields("Basin"), locations };
  await analyse({ kind: "basin", controls: spec.controls, guess: spec.start, grid: 80, jumps: 60, jump_limit: values.basin_jump_limit },
    (result) => plotBasin("basin-plot", result, "Basin of attraction", spec.start), fields);
});

on("#run-sweep", "click", async () => {
  const spec = await simControls();
  if (!spec) return;
  const psi0 = spec.controls[0].psi0_deg;
  await analyse({ kind: "sweep", psi0_deg: psi0, zeta0_low: 0.8, zeta0_high: 0.97, steps: 35, basin_grid: 20 },
    (result) => plotSweep("sweep-plot", result, `Symmetric gait at psi0 = ${psi0}° over zeta0`));
});
