// The Robot tab's run that follows a plan in a world, and every run's journal.
// A finished plan job is chosen (GET /jobs?kind=plan&state=done): its plan is drawn over its world
// (plan_view.js), and the run it starts is {plan_job_id, jumps, max_seconds, tracker_timeout_ms}
// (the plan's first two legs start it; the service's placement law sends each next leg). The
// journal: each command the run sent (its leg, why, and for a plan its target foothold), live
// from the status's ``recent_commands`` and, once the run is stored, from the stored run; a stored
// plan run's touchdowns are marked on the drawing where the feet met the world. Every value
// reaches the page as text or as SVG attributes.
import { $, call, on } from "./api.js";
import { element, fillTable } from "./dom.js";
import { frameOf, goalLine, targets } from "./plan_view.js";
import { drawWorld, segments, svgElement } from "./world_draw.js";
import { worldById } from "./world_list.js";

const form = () => $("#robot-run-form");
const LEG_INPUTS = ["psiL", "zetaL", "psiR", "zetaR", "closed_loop"];
const plans = new Map();  // plan job id -> {job, result} of the plans offered
const journal = { key: null, rows: [], stored: null, plan: null };  // the run shown: key, commands seen, stored id, plan job
let shown = null;  // the plan drawn: {id, job, result, drawn (world_draw's)}

const fixed = (value, digits) => (typeof value === "number" && Number.isFinite(value) ? value.toFixed(digits) : "—");
export const following = () => Boolean(form().elements.follow_plan.checked);

// The run's request body when it follows a plan (the fields checked by robot.js).
export function planRunBody(values) {
  return { plan_job_id: Number(form().elements.plan_job_id.value), jumps: values.jumps, max_seconds: values.max_seconds,
    tracker_timeout_ms: values.tracker_timeout_ms };
}

// The drawing shows the plan chosen, or the plan of the run shown (started here or elsewhere).
const showDrawing = () => { $("#robot-plan").hidden = !shown || !(following() || journal.plan === shown.id); };

// Following a plan, the legs and the closed loop are the plan's: their fields are disabled.
function followChanged() {
  const follow = following();
  for (const name of LEG_INPUTS) form().elements[name].disabled = follow;
  if (follow) form().elements.closed_loop.checked = false;
  form().elements.closed_loop.dispatchEvent(new Event("change"));
  form().elements.plan_job_id.disabled = !follow;
  showDrawing();
  if (follow) loadPlans().catch(() => {});
}
on("#follow-plan", "change", followChanged);
on("#plan-jobs-refresh", "click", () => loadPlans());
on("#plan-job", "change", () => showChosen());
followChanged();

// The finished plan jobs, newest first (the 100 newest): each offered with its world and goal;
// one that does not reach its goal is offered disabled, said why (the service would refuse it).
export async function loadPlans() {
  const page = await call("GET", "/jobs?kind=plan&state=done&limit=100");
  const select = $("#plan-job"), chosen = select.value;
  const fresh = page.items.filter((job) => !plans.has(job.id));  // results asked at once, not one after another
  const results = await Promise.all(fresh.map((job) => call("GET", `/jobs/${job.id}/results`)));
  fresh.forEach((job, k) => plans.set(job.id, { job, result: results[k].result }));
  const options = [];
  for (const job of page.items) {
    const { result } = plans.get(job.id);
    const world = (await worldById(job.world_id).catch(() => null))?.name ?? `world ${job.world_id}`;
    const reach = result?.reaches_goal ? `${result.plan.length} touchdowns` : `does not reach it (highest foot ${fixed(result?.highest_m, 3)} m)`;
    const option = element("option", `job ${job.id}: "${world}" to ${job.spec?.goal_height_m} m, ${reach}`);
    option.value = String(job.id);
    option.disabled = !result?.reaches_goal;
    options.push(option);
  }
  if (!options.length) options.push(Object.assign(element("option", "no finished plan job: plan one in the Jobs tab"), { value: "", disabled: true }));
  select.replaceChildren(...options);
  const offered = [...select.options].filter((option) => !option.disabled).map((option) => option.value);
  select.value = offered.includes(chosen) ? chosen : (offered[0] ?? "");
  await showChosen();
}

// The chosen plan over its world: its targets numbered, the goal dashed (plan_view.js's marks).
async function showChosen() { await showPlan(Number($("#plan-job").value)); }

// Plan job ``id`` over its world (fetched if not offered yet: a run another panel started).
async function showPlan(id) {
  if (!plans.has(id) && id > 0) plans.set(id, { job: await call("GET", `/jobs/${id}`), result: (await call("GET", `/jobs/${id}/results`)).result });
  const chosen = plans.get(id);
  if (!chosen || !chosen.result) { shown = null; showDrawing(); return; }
  const { job, result } = chosen;
  const world = job.spec?.world ?? (await worldById(job.world_id).catch(() => null))?.world;
  const steps = Array.isArray(result.plan) ? result.plan : [];
  const svg = $("#robot-plan-svg");
  const drawn = drawWorld(svg, world, { frame: frameOf(world, steps, result.goal_l0 ?? null), clip: "robot-plan-clip" });
  if (typeof result.goal_l0 === "number") svg.append(...goalLine(drawn, result.goal_l0, job.spec.goal_height_m));
  svg.append(...targets(drawn, steps));
  svg.setAttribute("aria-label", `The plan of job ${id}: ${steps.length} foot targets over its world`);
  shown = { id, job, result, world, drawn };
  $("#robot-plan-about").textContent = `Job ${id}'s plan: numbered circles are each touchdown's foot target (blue: left side, ` +
    `orange: right side); dark crosses, once a run of it is stored, where that run's feet met the world.`;
  showDrawing();
}

// A command's row: when (since the run's start), the leg sent, why, and for a plan its target.
function commandCells(command, started) {
  const target = command.target;
  const aim = target ? `touchdown ${target.touchdown}: ${target.side} segment ${target.segment} at (${fixed(target.x_m, 3)}, ${fixed(target.y_m, 3)}) m`
    : (command.controller ?? "—");
  return [fixed(command.time - started, 2), command.leg, fixed(command.psi0_deg, 1), fixed(command.zeta0, 3), command.why ?? "—",
    aim, command.placed ?? "—", command.clipped ? "clipped" : "no"];
}

// A command missed (this panel saw no status while it was among the newest) is a row saying so.
function showJournal(started) {
  const rows = Array.from(journal.rows, (command, index) => element("tr", null, element("td", String(index + 1)),
    ...(command ? commandCells(command, started) : ["—", "—", "—", "—", "not seen live: in the journal once stored", "—", "—", "—"])
      .map((text) => element("td", String(text)))));
  fillTable("#robot-journal", rows, "No command sent yet.");
  $("#robot-journal").hidden = false;
}

// Each status's run (robot.js): a new run's journal starts afresh; a command not seen yet is
// added; once the run is stored, its journal is read whole from the store.
export function followJournal(run) {
  if (!run || typeof run.started !== "number") return;
  const key = `${run.id ?? ""}@${run.started}`;
  if (key !== journal.key) {
    Object.assign(journal, { key, rows: [], stored: null, plan: run.plan_job_id ?? null });
    $("#robot-journal-caption").textContent = `Run ${run.id ?? ""}'s journal: each command, as it is sent` +
      `${journal.plan ? `, aimed at plan job ${journal.plan}'s footholds` : ""}.`;
    fillTable("#robot-journal", [], "No command sent yet.");
    $("#robot-plan-svg").querySelectorAll(".run-foot").forEach((node) => node.remove());
    if (journal.plan && shown?.id !== journal.plan) showPlan(journal.plan).catch(() => {});
    showDrawing();
  }
  // The status's newest commands are commands run.commands - recent.length + 1 ... run.commands.
  const recent = Array.isArray(run.recent_commands) ? run.recent_commands : [];
  const first = run.commands - recent.length;
  if (journal.stored === null && recent.length && run.commands > journal.rows.length) {
    recent.forEach((command, k) => { journal.rows[first + k] = command; });
    showJournal(run.started);
  }
  if (!run.active && run.stored_run_id != null && journal.stored !== run.stored_run_id) {
    journal.stored = run.stored_run_id;
    storedJournal(run.stored_run_id, run.started).catch(() => {});
  }
}

async function storedJournal(runId, started) {
  const stored = await call("GET", `/runs/${runId}`);
  const results = stored.results ?? {};
  journal.rows = Array.isArray(results.commands) ? results.commands : [];
  showJournal(started);
  $("#robot-journal-caption").textContent = `Run ${runId}'s journal (as stored): each command the run sent` +
    `${results.plan_job_id ? `, aimed at plan job ${results.plan_job_id}'s footholds` : ""}; it ended "${results.end_reason ?? "—"}".`;
  if (!results.plan_job_id) return;
  if (shown?.id !== results.plan_job_id) await showPlan(results.plan_job_id);  // a run this panel did not start
  if (shown?.id === results.plan_job_id) markFeet(results.touchdowns ?? [], shown.result.leg_length_m);
}

// Where a side is at height ``y`` [l0]: its segment spanning y, interpolated (null: none does).
function sideX(world, side, y) {
  const spanning = segments(world, side).find((s) => Math.min(s.a[1], s.b[1]) <= y && y <= Math.max(s.a[1], s.b[1]));
  if (!spanning) return null;
  const [a, b] = [spanning.a, spanning.b];
  return b[1] === a[1] ? a[0] : a[0] + ((y - a[1]) / (b[1] - a[1])) * (b[0] - a[0]);
}

// The stored run's touchdowns on the drawing: a cross where each foot met its side (touchdown
// heights in metres; the world in l0).
function markFeet(touchdowns, legLength) {
  if (typeof legLength !== "number" || !(legLength > 0)) return;
  const svg = $("#robot-plan-svg");
  svg.querySelectorAll(".run-foot").forEach((node) => node.remove());
  touchdowns.forEach((touchdown, index) => {
    const side = touchdown.wall === 1 ? "right" : "left", y = touchdown.foot_height / legLength;
    const x = sideX(shown.world, side, y);
    if (x === null) return;
    const [cx, cy] = shown.drawn.toSvg(x, y);
    const mark = svgElement("g", { class: "run-foot", "data-touchdown": index + 1 });
    const cross = `M${cx - 8},${cy - 8}L${cx + 8},${cy + 8}M${cx - 8},${cy + 8}L${cx + 8},${cy - 8}`;
    mark.append(svgElement("path", { d: cross, stroke: "white", "stroke-width": 5 }),  // a halo: seen over its target's circle
      svgElement("path", { d: cross, stroke: "#1d2733", "stroke-width": 2.5 }),
    svgElement("title", {}, `touchdown ${index + 1}: ${side} side, foot at ${fixed(touchdown.foot_height, 3)} m`));
    svg.append(mark);
  });
}
