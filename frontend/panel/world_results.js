// The results of the other jobs in worlds, in the Jobs tab: a foothold study (backend/jobs/
// foothold_study.py, ``parkour foothold-study --json``) as a row per method — reached of trials,
// failures by code, mean jumps, the planning's time — and a row per world; a world-mjtf job's
// climbs in words; a reach job in the jobs table's words (its result: reach_view.js). Every value
// reaches the page as text.
import { $ } from "./api.js";
import { element, fillTable } from "./dom.js";

const BOX = "#job-footholds";
const METHODS = { "open-loop": "open-loop (the best fixed leg)", placement: "placement (following a plan)" };

export function hideWorldResults() {
  $(BOX).hidden = true;
}

const fixed = (value, digits) => (typeof value === "number" && Number.isFinite(value) ? value.toFixed(digits) : "—");
const counts = (byCode) => Object.entries(byCode ?? {}).map(([code, n]) => `${code.replaceAll("_", " ")} ${n}`).join(", ") || "none";
const share = (reached, trials) => `${reached}/${trials}${trials ? ` (${(100 * reached / trials).toFixed(0)}%)` : ""}`;

// A method's row: as its text is checked against the API's result (tests/frontend/test_jobs_in_world_browser.py).
export const methodCells = (name, method) => [METHODS[name] ?? name, share(method.reached, method.trials), counts(method.failures_by_code),
  fixed(method.mean_jumps, 1), fixed(method.plan_seconds_median, 2), fixed(method.law_us_per_jump, 1)];

export function showFootholdStudy(id, job, result) {
  const worlds = result.worlds ?? [];
  const where = job.world_id ? `world #${job.world_id}${worlds[0] ? ` "${worlds[0].world}"` : ""}` : `${worlds.length} random world(s)`;
  $("#job-footholds-about").textContent = `Job ${id}: foothold study on ${where}, to a foot at ${fixed(result.goal_height_m, 3)} m, ` +
    `${result.trials_per_world} trial(s) a world and method on the same noise (seeds from ${result.seed}).` +
    `${typeof result.methods?.placement?.replans_per_trial === "number" ? ` Placement replanned ${fixed(result.methods.placement.replans_per_trial, 2)} times a trial.` : ""}`;
  const methods = Object.entries(result.methods ?? {});
  fillTable("#job-footholds-methods", methods.map(([name, method]) => element("tr", null, ...methodCells(name, method).map((text) => element("td", text)))),
    "No methods.");
  fillTable("#job-footholds-worlds", worlds.map((world) => element("tr", null, element("td", world.world),
    element("td", world.plan_exists ? "yes" : "none found"), element("td", String(world.trials)),
    ...Object.keys(METHODS).map((name) => element("td", share(world.reached?.[name] ?? 0, world.trials))))), "No worlds.");
  $(BOX).hidden = false;
}

// A world-mjtf job in words: the mean jumps and how the trials ended.
export function worldMjtfWords(id, result) {
  const goal = typeof result.goal_height_m === "number" ? `, to a foot at ${result.goal_height_m} m` : "";
  return `Job ${id}: ${result.trials} climb(s) in "${result.world}"${goal}: ${fixed(result.mean_jumps, 1)} ± ${fixed(result.std_jumps, 1)} jumps; ` +
    `ended: ${counts(result.outcomes)}.`;
}

// A job in a world, for the jobs table's "what" (null: not one).
export function worldJobWords(job) {
  const spec = job.spec || {};
  const world = spec.random_worlds ? `${spec.random_worlds.count} random world(s) from seed ${spec.random_worlds.seed0 ?? 0}` : `world #${spec.world_id}`;
  const goal = typeof spec.goal_height_m === "number" ? ` to ${spec.goal_height_m} m` : "";
  if (job.kind === "plan") return `plan up ${world}${goal}${spec.attempts ? `, ${spec.attempts} noisy climbs` : ""}`;
  if (job.kind === "foothold-study") return `${world}${goal}, ${spec.trials} trials a world and method`;
  if (job.kind === "reach") {
    const range = (pair, unit) => (Array.isArray(pair) ? `${pair.join("–")}${unit}` : "");
    return `reach of ${spec.psi0_steps} psi0 (${range(spec.psi0_range, "°")}) × ${spec.zeta0_steps} zeta0 (${range(spec.zeta0_range, "")}) ` +
      `in ${world}, up to ${spec.jumps} jumps`;
  }
  if (job.kind === "world-mjtf") {
    const legs = (spec.controls || []).map((leg) => `${leg.psi0_deg}°/${leg.zeta0}`).join(", ");
    return `${legs} in ${world}${goal}, ${spec.trials} trials`;
  }
  return null;
}
