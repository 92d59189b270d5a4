// A plan job's result over its world (backend/jobs/plan.py: ``parkour plan --json`` plus the
// world's name and the start's velocity): the world the job planned in drawn (world_draw.js; the
// job's spec holds it in l0, the frame the plan's targets are in), each touchdown's foot target
// marked and numbered by jump and coloured by side, the goal height as a dashed line, and the
// steps as a table; the chance, the highest foot and the Monte-Carlo climbs in words. Every value
// reaches the page as text or as SVG attributes.
import { $, API } from "./api.js";
import { element, fillTable } from "./dom.js";
import { drawWorld, extent, svgElement } from "./world_draw.js";
import { worldById } from "./world_list.js";

const BOX = "#job-plan";
export const SIDE_COLORS = { left: "#2c6fb7", right: "#e08a00" };

export function hidePlan() {
  $(BOX).hidden = true;
  $("#job-plan-svg").replaceChildren();
}

// A preset's leg length l0 [m] (the goal is in metres, the world and the targets in l0): what a
// one-jump trajectory of that preset says (its "si"), asked once a preset; null if it cannot be
// had (then the goal is said, not drawn). A plain fetch: a failure here is no error of the user's.
const legLengths = new Map();
export function legLength(preset, state) {
  if (!legLengths.has(preset)) {
    const body = { model: { preset }, controls: [{ psi0_deg: 30, zeta0: 0.9 }], jumps: 1, rate: 1,
      start: { xdot: state?.[0] < 0 ? state[0] : -0.93, ydot: state?.[1] ?? -0.2 } };
    legLengths.set(preset, fetch(`${API}/sim/trajectory`, { method: "POST", body: JSON.stringify(body),
      headers: { "Content-Type": "application/json", "X-Parkour-Client": "panel" } })
      .then((response) => (response.ok ? response.json() : null)).then((path) => path?.si?.l0_m ?? null).catch(() => null));
  }
  return legLengths.get(preset);
}

const fixed = (value, digits) => (typeof value === "number" && Number.isFinite(value) ? value.toFixed(digits) : "—");
const percent = (value) => `${(100 * value).toFixed(1)}%`;

// A step's row, as its text is checked against the API's result (tests/frontend/test_jobs_in_world_browser.py).
export const stepCells = (step) => [String(step.jump), step.side, String(step.segment), fixed(step.target?.[0], 3),
  fixed(step.target?.[1], 3), fixed(step.psi0_deg, 1), fixed(step.zeta0, 3)];

// The plan in words: whether it reaches the goal, its chance, the highest foot, the climbs.
export function planWords(id, job, result, worldName) {
  const steps = result.plan?.length ?? 0;
  const reached = result.reaches_goal
    ? `reaches the goal ${job.spec.goal_height_m} m in ${steps} touchdown(s)`
    : `does not reach the goal ${job.spec.goal_height_m} m: its highest foot is at ${fixed(result.highest_m, 3)} m`;
  const words = [`Job ${id}: the plan up "${worldName}" ${reached}; estimated chance to get through ${fixed(result.chance, 3)}, ` +
    `highest foot ${fixed(result.highest_m, 3)} m, found in ${fixed(result.seconds, 1)} s.`];
  const mc = result.monte_carlo;
  if (mc) {
    const [low, high] = mc.failure_chance_ci95 ?? [];
    words.push(`${mc.trials} noisy climbs by the placement law: ${mc.failures} failed (${percent(mc.failures / mc.trials)}` +
      `${typeof low === "number" ? `, 95%: ${percent(low)}–${percent(high)}` : ""}), ${fixed(mc.mean_attempt_jumps, 1)} jumps a climb on average` +
      `${mc.mfpt_jumps ? `, about ${Math.round(mc.mfpt_jumps)} jumps to a failure` : ""}.`);
  }
  const is = result.importance_sampling;
  if (is) {
    const [low, high] = is.failure_chance_ci95 ?? [];
    const widened = `${(is.scaled ?? []).join(", ")} draws × ${is.scale}${is.first_leg_only ? " at touchdown 0" : ""}`;
    words.push(`${is.trials} importance-sampled climbs (${widened}): failure chance ${fixed(is.failure_chance, 6)}` +
      `${typeof low === "number" ? ` (95%: ${fixed(low, 6)}–${fixed(high, 6)})` : ""}, effective sample size ` +
      `${fixed(is.effective_sample_size, 0)}${is.warning ? ` — ${is.warning}` : ""}.`);
  }
  return words.join(" ");
}

export async function showPlan(id, job, result) {
  const spec = job.spec || {};
  const stored = await worldById(job.world_id ?? spec.world_id).catch(() => null);
  const worldName = stored?.name ?? result.world ?? `world ${job.world_id}`;
  const steps = Array.isArray(result.plan) ? result.plan : [];
  $("#job-plan-title").textContent = `Job ${id}: a plan up world #${job.world_id ?? spec.world_id}, "${worldName}"`;
  $("#job-plan-about").textContent = planWords(id, job, result, worldName);
  fillTable("#job-plan-steps", steps.map((step) => element("tr", null, ...stepCells(step).map((text) => element("td", text)))),
    "No touchdowns: no leg gets the robot off the floor.");
  const svg = $("#job-plan-svg"), world = spec.world ?? stored?.world;
  // The result says the goal in l0 (plans made before it did: from the preset's leg length, asked).
  const l0 = result.goal_l0 === undefined ? await legLength(spec.model?.preset ?? "paper", result.state) : null;
  const goal = result.goal_l0 ?? (l0 ? spec.goal_height_m / l0 : null);
  const drawn = drawWorld(svg, world, { frame: frameOf(world, steps, goal), clip: "job-plan-clip" });
  svg.setAttribute("aria-label", `World "${worldName}" with the plan's ${steps.length} foot targets`);
  if (goal !== null) svg.append(...goalLine(drawn, goal, spec.goal_height_m));
  svg.append(...targets(drawn, steps));
  $("#job-plan-key").textContent = `Numbered circles: each touchdown's foot target (blue: left side, orange: right side), ` +
    `joined in order. ${goal === null ? `The goal, ${spec.goal_height_m} m, is not drawn (the leg length was not to be had).`
      : `Dashed: the goal, ${spec.goal_height_m} m = ${goal.toFixed(3)} l0.`} The sides: coloured by friction, footholds ticked as in the World tab; drawn up to a little above the plan.`;
  $(BOX).hidden = false;
}

// The world's extent up to a little above the plan's top (its highest target or the goal): a
// tall world's climb is not squeezed into the bottom of the drawing.
export function frameOf(world, steps, goal) {
  const frame = extent(world);
  const top = Math.max(goal ?? -Infinity, ...steps.map((step) => step.target?.[1] ?? -Infinity));
  if (!Number.isFinite(top)) return frame;
  return { ...frame, ymax: Math.min(frame.ymax, top + Math.max(1, 0.25 * (top - frame.ymin))) };
}

export function goalLine({ frame, toSvg }, goal, metres) {
  const [x1, y] = toSvg(frame.xmin, goal), [x2] = toSvg(frame.xmax, goal);
  return [svgElement("line", { x1, x2, y1: y, y2: y, class: "plan-goal" }),
    svgElement("text", { x: x2 + 6, y: y + 4, class: "plan-goal-text" }, `goal ${metres} m`)];
}

// The targets joined in order, then each as a numbered circle with its step in a tooltip.
export function targets({ toSvg }, steps) {
  const points = steps.filter((step) => Array.isArray(step.target)).map((step) => ({ step, at: toSvg(...step.target) }));
  const nodes = [];
  if (points.length > 1) {
    nodes.push(svgElement("polyline", { points: points.map(({ at }) => at.join(",")).join(" "), class: "plan-path" }));
  }
  for (const { step, at: [cx, cy] } of points) {
    const mark = svgElement("g", { class: "plan-target", "data-jump": step.jump, "data-side": step.side });
    const colour = SIDE_COLORS[step.side] ?? "#555";
    mark.append(svgElement("circle", { cx, cy, r: 9, fill: colour }),
      svgElement("text", { x: cx, y: cy + 4, "text-anchor": "middle", class: "plan-number" }, String(step.jump)),
      svgElement("title", {}, `jump ${step.jump}: ${step.side} segment ${step.segment}, target (${stepCells(step).slice(3, 5).join(", ")}) l0, ` +
        `psi0 ${fixed(step.psi0_deg, 1)}°, zeta0 ${fixed(step.zeta0, 3)}`));
    nodes.push(mark);
  }
  return nodes;
}
