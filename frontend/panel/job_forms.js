// The Jobs tab's form: the kind chooser from the service's catalog, each kind's fields checked
// against its request's ranges, and the body to send (jobSpec).
//
// Forms made from the API: a job kind the page has no form for gets one built from its
// request body's schema in the OpenAPI document (the catalog names it): a number field per
// property that takes a plain number — or a list of them, comma-separated (a reach job's range:
// low, high) — its default filled in, its description as its title, its range checked as every
// form's is (fields.js; a list's count and order are the API's to say) — and a fieldset per
// property that is an object of its own (a starting state, the noise, a plan's importance
// sampling: job_object_fields.js), an optional one behind its checkbox "set <name>". A kind whose
// body needs more (legs, a list of names) is left to its own fieldset in index.html, or to the API
// — save a stored world (a chooser of worlds by name, a foothold study's random worlds, a
// world-mjtf job's legs: job_world.js). So a job kind added to the service's registry can be
// scheduled from the panel with no change here.
import { $, say, on } from "./api.js";
import { Fields } from "./fields.js";
import { attributes, element } from "./dom.js";
import { SQRT_GL0, checked, simControls } from "./forms.js";
import { loadCatalog } from "./catalog.js";
import { WORLD_PARTS, worldPart } from "./job_world.js";
import { objectField, words } from "./job_object_fields.js";

// The kind is the chooser's, the experiment the "in experiment" choice's; no job form sets the
// model (each job runs the paper's, the service's default, as the forms in index.html do).
const SKIPPED = new Set(["kind", "experiment_id", "model"]);

// The simple number properties of ``kind``'s request, its object fields (job_object_fields.js) and
// the names of its world's properties (job_world.js), or null when a required one is none of these.
async function numberFields(kind) {
  const schema = await Fields.schema(kind.request);
  if (!schema?.properties) return null;
  const required = new Set(schema.required || []);
  const fields = [], world = [], objects = [], switches = [];
  for (const [name, property] of Object.entries(schema.properties)) {
    if (SKIPPED.has(name)) continue;
    if (WORLD_PARTS.has(name)) {
      world.push(name);
      continue;
    }
    const plain = Fields.plain(property);
    if (plain?.type === "boolean") {  // a yes/no of the request's own (a plan's launch_gait): a checkbox
      switches.push({ name, initial: plain.default === true, title: property.description ?? plain.description ?? "" });
      continue;
    }
    const items = plain?.type === "array" ? Fields.plain(plain.items) : null;  // a list of numbers, or not
    if (!["number", "integer"].includes((items ?? plain)?.type)) {
      const object = objectField(kind.name, kind.request, name, property, required.has(name));
      if (object) objects.push(object);
      else if (required.has(name)) return null;
      continue;
    }
    fields.push({ name, plain, list: items !== null, required: required.has(name), title: property.description ?? plain.description ?? "" });
  }
  return { fields, world, objects, switches };
}

// A fieldset for ``kind`` ({name, title, request}) built from its schema, or null if it cannot be.
async function generatedFieldset(kind) {
  const found = await numberFields(kind);
  if (!found) return null;
  const { fields, objects } = found;
  const part = found.world.length ? worldPart(kind.name, found.world) : null;
  if (found.world.length && !part) return null;
  const fieldset = attributes(element("fieldset", null, element("legend", kind.title), ...(part?.nodes ?? [])),
    { "data-kind": kind.name, "data-generated": "" });
  for (const field of fields) {
    const input = attributes(element("input", null), field.list ? { name: `${kind.name}__${field.name}`, size: 12 }
      : { name: `${kind.name}__${field.name}`, type: "number", step: field.plain.type === "integer" ? "1" : "any" });
    const initial = field.plain.default;
    if (initial !== undefined && initial !== null) input.value = Array.isArray(initial) ? initial.join(", ") : String(initial);
    const label = element("label", `${words(field.name)} `, input);  // goal_height_m: "goal height [m]"
    if (field.title) label.title = field.title;
    fieldset.append(label);
  }
  for (const flag of found.switches) {
    const box = attributes(element("input", null), { name: `${kind.name}__${flag.name}`, type: "checkbox" });
    box.checked = flag.initial;
    const label = attributes(element("label", null, box, ` ${words(flag.name)}`), { class: "inline" });
    if (flag.title) label.title = flag.title;
    fieldset.append(label);
  }
  fieldset.append(...objects.map((object) => object.node));
  fieldset.hidden = true;
  fieldset.disabled = true;
  const numbers = fields.map((field) => ({ name: `${kind.name}__${field.name}`, rule: `${kind.request}.${field.name}`, optional: !field.required,
    list: field.list }));
  return { fieldset, fields: numbers, part, objects, switches: found.switches.map((flag) => flag.name) };
}

// The body and the 422's locations of a generated kind's form, from the checked values ``v``
// (null: its world's part marked a field).
function generatedBody(form, kind, { fields, part, objects, switches }, v) {
  const body = { kind }, locations = { ...part?.locations };
  for (const name of switches) {
    body[name] = form.elements[`${kind}__${name}`].checked;
    locations[name] = `${kind}__${name}`;
  }
  for (const field of fields) {
    const property = field.name.slice(kind.length + 2);
    if (v[field.name] !== undefined) body[property] = v[field.name];
    locations[property] = field.name;
  }
  for (const object of objects) {
    const value = object.value(form, v);
    if (value !== undefined) body[object.name] = value;
    Object.assign(locations, object.locations);
  }
  const world = part ? part.body(form, v) : {};
  if (world === null) return null;
  for (const [property, input] of Object.entries(locations)) locations[`${kind}.${property}`] = input;
  return { body: { ...body, ...world }, locations };
}

on("#job-kind", "change", (event) => {
  for (const fieldset of document.querySelectorAll("#job-form fieldset[data-kind]")) {
    fieldset.hidden = fieldset.dataset.kind !== event.target.value;
    fieldset.disabled = fieldset.hidden;  // hidden fields are neither validated nor sent
  }
});

// The kind chooser, from the service's catalog: a kind with its own fieldset in index.html, or
// one built from its request's schema (job_forms.js), in the registry's order; a kind whose
// body the panel cannot build (a gait search's legs) is left to the API.
const GENERATED = new Map();  // kind -> its generated form: {fieldset, fields, part (its world's: job_world.js), objects, switches}
async function fillJobKinds() {
  const form = $("#job-form"), select = $("#job-kind");
  const options = [];
  for (const kind of (await loadCatalog()).job_kinds) {
    if (!form.querySelector(`fieldset[data-kind="${kind.name}"]`)) {
      const made = await generatedFieldset(kind);
      if (!made) continue;
      GENERATED.set(kind.name, made);
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
export async function jobSpec(form) {
  const kind = form.elements.kind.value;
  const made = GENERATED.get(kind);
  const v = await checked(form, JOB_FIELDS[kind]
    ?? [...made.fields, ...(made.part?.fields(form) ?? []), ...made.objects.flatMap((object) => object.fields(form))]);
  // Its world chosen and its lists of names counted, each marked where it is not (all in this one pass).
  const refused = made ? [made.part && !made.part.chosen(form), ...made.objects.map((object) => !object.valid(form))] : [];
  if (refused.some(Boolean)) {
    if (v !== null) say("Fix the marked field(s) first: nothing was sent.", "error");
    return null;
  }
  if (v === null) return null;
  if (made) return generatedBody(form, kind, made, v);
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
