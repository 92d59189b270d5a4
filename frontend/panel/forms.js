// What the forms share: the legs' and start's fields with their API rules (fields.js checks
// them), a 422's locations on the Simulate form, checking fields with the banner, and the
// experiment a form files its run or job under.
import { Fields } from "./fields.js";
import { $, say } from "./api.js";

// The experiment a form files its run or job under (the form's "in experiment" choice), as the
// request's experiment_id; none: not filed.
export function filedUnder(form) {
  const value = form.elements.experiment_id?.value;
  return value ? { experiment_id: Number(value) } : {};
}

// Each action checks the fields it sends against the request body it sends them in (jumps: up
// to 50 for a drawn trajectory, 10,000 for a stored run), from the API's own ranges (fields.js).
export const SQRT_GL0 = "√(g l0)";
export const LEG_FIELDS = [
  { name: "psiL", rule: "LegIn.psi0_deg", unit: "°" }, { name: "zetaL", rule: "LegIn.zeta0", unit: "l0" },
  { name: "psiR", rule: "LegIn.psi0_deg", unit: "°" }, { name: "zetaR", rule: "LegIn.zeta0", unit: "l0" },
];
const START_FIELDS = [{ name: "xdot", rule: "StateIn.xdot", unit: SQRT_GL0 }, { name: "ydot", rule: "StateIn.ydot", unit: SQRT_GL0 }];
export const SIM_LOCATIONS = {
  "controls.0.psi0_deg": "psiL", "controls.0.zeta0": "zetaL", "controls.1.psi0_deg": "psiR", "controls.1.zeta0": "zetaR",
  "start.xdot": "xdot", "start.ydot": "ydot", "guess.xdot": "xdot", "guess.ydot": "ydot", jumps: "jumps", psi0_deg: "psiL",
};
// ``action``: the button's name, before what the service says no field of the form takes.
export const simFields = (action) => ({ form: $("#sim-form"), locations: SIM_LOCATIONS, action });

// The checked values of ``fields`` in ``form``, or null (the bad ones are marked; the banner says so).
export async function checked(form, fields) {
  const values = await Fields.readFields(form, fields);
  if (values === null) say("Fix the marked field(s) first: nothing was sent.", "error");
  else for (const banner of document.querySelectorAll("#messages .message.error")) banner.remove();
  return values;
}

// The Simulate form's legs and start (and ``jumps`` by ``jumpsRule``), or null.
export async function simControls(jumpsRule) {
  return (await simControlsWith([], jumpsRule))?.spec ?? null;
}

// As simControls, with ``extra`` fields of the form checked in the same pass (a pass clears the
// marks of the one before): {spec, values: every field's value}, or null.
export async function simControlsWith(extra, jumpsRule) {
  const fields = [...LEG_FIELDS, ...START_FIELDS, ...(jumpsRule ? [{ name: "jumps", rule: jumpsRule, unit: "jumps" }] : []), ...extra];
  const v = await checked($("#sim-form"), fields);
  if (v === null) return null;
  const spec = {
    controls: [{ psi0_deg: v.psiL, zeta0: v.zetaL }, { psi0_deg: v.psiR, zeta0: v.zetaR }],
    start: { xdot: v.xdot, ydot: v.ydot }, jumps: v.jumps,
  };
  return { spec, values: v };
}
