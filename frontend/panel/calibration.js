// History → calibration: fit the model (alpha, c_zeta, c_psi and the legs' offsets) to the
// selected robot and replay runs, stored as a named preset; the fit's report (value ± standard
// error, the residuals before and after, what the runs cannot tell apart, the noise left); the
// stored calibrations, each shown or deleted. Every value from the API reaches the page as text.
import { $, say, call, on } from "./api.js";
import { Fields } from "./fields.js";
import { element, fillTable, attributes } from "./dom.js";
import { RECORDED_KINDS, selectedRuns } from "./history.js";

const NONDIMENSIONAL = "nondimensional";
// The report's rows: a label, the value and its standard error from the fit, the unit.
const PARAMETER_ROWS = [
  ["alpha", (p) => p.alpha, NONDIMENSIONAL], ["c_zeta", (p) => p.c_zeta, NONDIMENSIONAL], ["c_psi", (p) => p.c_psi, NONDIMENSIONAL],
  ["psi0 offset, left leg", (p) => p.psi0_offset_deg[0], "deg"], ["psi0 offset, right leg", (p) => p.psi0_offset_deg[1], "deg"],
  ["zeta0 offset, left leg", (p) => p.zeta0_offset[0], "l0"], ["zeta0 offset, right leg", (p) => p.zeta0_offset[1], "l0"],
];
const PARAMETER_WORDS = { "psi0_offset_deg.left": "psi0 offset (left)", "psi0_offset_deg.right": "psi0 offset (right)",
  "zeta0_offset.left": "zeta0 offset (left)", "zeta0_offset.right": "zeta0 offset (right)" };
const UNIT_WORDS = { "sqrt(g l0)": "√(g l0)" };
// The fit's noise sigmas (sim_core.calibration.noise): where each enters, and its unit.
const NOISE_WORDS = { state_input: ["touchdown state as measured", "√(g l0)"], psi0_deg: ["psi0 as realised", "deg"],
  zeta0: ["zeta0 as realised", "l0"], state_output: ["next touchdown's state as measured", "√(g l0)"], rise: ["rise as measured", "l0"] };

export const number = (value, digits = 4) =>
  (value === null || value === undefined ? "—" : String(Number(Number(value).toPrecision(digits))));
const unitOf = (unit) => UNIT_WORDS[unit] ?? unit;

// The fit's report: what a person reads to decide whether to trust the preset.
export function fitReport(fit) {
  const rows = PARAMETER_ROWS.map(([label, pick, unit]) => {
    const error = pick(fit.stderr);
    const cell = error === null ? `${number(pick(fit.params))} (not identifiable)` : `${number(pick(fit.params))} ± ${number(error, 2)}`;
    return element("tr", null, element("td", label), attributes(element("td", cell), { class: error === null ? "value unidentified" : "value" }),
      element("td", unit));
  });
  const table = element("table", null, element("caption", `Calibration ${fit.preset.name}: fitted from ${fit.preset.base}`),
    element("tr", null, element("th", "parameter"), element("th", "value ± standard error"), element("th", "unit")), ...rows);
  table.id = "calibration-params";
  const channels = Object.entries(fit.residuals || {}).map(([channel, r]) =>
    `${channel} ${number(r.rms_before)} → ${number(r.rms_after)} ${unitOf(r.unit)}`);
  const noise = Object.entries(fit.noise || {}).map(([source, value]) => {
    const [words, unit] = NOISE_WORDS[source] ?? [source, ""];
    return `${words} ${number(value, 2)} ${unit}`.trim();
  });
  const lines = [
    attributes(element("p", `RMS residual ${number(fit.rms_residual_before)} → ${number(fit.rms_residual_after)} √(g l0) `
      + `(the one-jump section-state error, ${fit.preset.base} → fitted), over ${fit.touchdowns_used} touchdowns`
      + `${fit.failed_predictions ? `; ${fit.failed_predictions} predictions failed` : ""}.`), { class: "rms" }),
    attributes(element("p", `Per channel: ${channels.join("; ")}.`), { class: "channels" }),
    attributes(element("p", `Noise estimated (σ): ${noise.join("; ")}.`), { class: "noise" }),
    attributes(element("p", `From runs ${fit.preset.runs.join(", ")}; ${new Date(fit.preset.created_at).toLocaleString()}, code ${fit.preset.code_version}.`),
      { class: "provenance" }),
  ];
  if (fit.confounded.length) {
    const pairs = fit.confounded.map(([a, b, r]) => `${PARAMETER_WORDS[a] ?? a} and ${PARAMETER_WORDS[b] ?? b} (correlation ${number(r, 2)})`);
    lines.unshift(attributes(element("p", `The runs cannot tell apart: ${pairs.join("; ")}. They fix a combination better than either; runs at more varied legs would separate them.`),
      { class: "warning confounded", role: "note" }));
  }
  if (fit.unidentifiable.length) {
    lines.unshift(attributes(element("p", `Not identifiable from these runs: ${fit.unidentifiable.map((p) => PARAMETER_WORDS[p] ?? p).join(", ")}.`),
      { class: "warning unidentifiable", role: "note" }));
  }
  const box = element("div", null, table, ...lines);
  box.className = "fit-report";
  return box;
}

function showFit(fit) {
  $("#calibrations-box").open = true;
  $("#calibration-out").replaceChildren(fitReport(fit));
}

const storedFits = new Map();  // name -> the calibration as last listed

// The stored calibrations: the table in History and every "calibrated model" choice.
export async function loadCalibrations() {
  const { items } = await call("GET", "/calibrations");
  storedFits.clear();
  items.forEach((fit) => storedFits.set(fit.preset.name, fit));
  fillTable("#calibration-table", items.map((fit) => {
    const name = fit.preset.name;
    const row = element("tr", null,
      element("td", null, attributes(element("button", name), { type: "button", class: "show-calibration", "data-name": name,
        "aria-label": `show calibration ${name}` })),
      element("td", fit.preset.runs.join(", ")), element("td", String(fit.touchdowns_used)),
      element("td", `${number(fit.rms_residual_before)} → ${number(fit.rms_residual_after)}`),
      element("td", new Date(fit.preset.created_at).toLocaleString()),
      element("td", null, attributes(element("button", "delete"), { type: "button", class: "delete-calibration secondary", "data-name": name,
        "aria-label": `delete calibration ${name}` })));
    row.dataset.name = name;
    return row;
  }), "No calibrations yet: select robot or replay runs above and Calibrate.");
  for (const choice of document.querySelectorAll("select.preset-choice")) {
    const kept = choice.value;
    choice.replaceChildren(choice.options[0], ...items.map((fit) => new Option(fit.preset.name, fit.preset.name)));
    choice.value = storedFits.has(kept) ? kept : "";
  }
  return items;
}

on("#calibration-table", "click", async (event) => {
  const shown = event.target.closest("button.show-calibration");
  if (shown) return showFit(storedFits.get(shown.dataset.name));
  const doomed = event.target.closest("button.delete-calibration");
  if (!doomed) return;
  const name = doomed.dataset.name;
  if (!window.confirm(`Delete calibration ${name}? Runs and jobs that used it keep their results.`)) return;
  await call("DELETE", `/calibrations/${encodeURIComponent(name)}`);
  if ($("#calibration-params caption")?.textContent.startsWith(`Calibration ${name}:`)) $("#calibration-out").replaceChildren();
  await loadCalibrations();
  say(`Calibration ${name} deleted.`);
});

// "Calibrate selected…": the robot and replay runs ticked, a name, then the fit (seconds).
let calibrating = [];
on("#calibrate", "click", () => {
  const chosen = selectedRuns();
  calibrating = chosen.filter((run) => RECORDED_KINDS.includes(run.kind)).map((run) => run.id).sort((a, b) => a - b);
  if (!calibrating.length) return say("Select one or more robot or replay runs to calibrate from (simulated runs have no measurements).", "error");
  const left = chosen.filter((run) => !RECORDED_KINDS.includes(run.kind)).map((run) => run.id);
  $("#calibrate-runs").textContent = `From runs ${calibrating.join(", ")}${left.length ? ` (simulated runs ${left.join(", ")} left out: nothing measured)` : ""}.`;
  $("#calibrate-status").textContent = "";
  const dialog = $("#calibrate-dialog");
  dialog.returnValue = "";
  dialog.showModal();
  dialog.querySelector("input[name=name]").focus();
});
on("#calibrate-cancel", "click", () => $("#calibrate-dialog").close());

on("#calibrate-form", "submit", async (event) => {
  event.preventDefault();
  const form = event.target;
  const status = $("#calibrate-status");
  const fit = $("#calibrate-fit");
  Fields.clear(form);
  status.textContent = `Fitting to ${calibrating.length} run${calibrating.length > 1 ? "s" : ""}… (seconds)`;
  fit.disabled = true;
  try {
    const result = await call("POST", "/calibrations", { runs: calibrating, name: form.elements.name.value.trim() },
      { form, locations: { name: "name" } });
    $("#calibrate-dialog").close();
    form.reset();
    showFit(result);
    await loadCalibrations();
    say(`Calibration ${result.preset.name} stored: RMS residual ${number(result.rms_residual_before)} → ${number(result.rms_residual_after)} √(g l0).`);
  } catch (error) {
    status.textContent = `Not stored: ${error.message}`;  // the field, when it is one, is marked too
    throw error;
  } finally {
    fit.disabled = false;
  }
});
