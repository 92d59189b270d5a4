// History → "Compare basket": the basket's runs side by side (GET /api/v1/runs/compare), only
// what differs, in a person's terms: legs by side, dates in local time, numbers to 6 significant
// digits, how each run ended and was driven. Every value (notes included) goes in as text.
import { $, say, call, on } from "./api.js";
import { element } from "./dom.js";
import { basketIds } from "./basket.js";

const LEG_SIDES = ["left", "right"];
const COMPARE_LABELS = { created_at: "created", duration_s: "computed in [s]", climb: "climb [l0]",
  start_xdot: "start xdot [√(g l0)]", start_ydot: "start ydot [√(g l0)]", jumps_completed: "jumps completed",
  failure_code: "failure", code_version: "code version", experiment_id: "experiment", end_reason: "ending",
  loop: "loop", controller: "controller", target: "target [m]", touchdowns: "touchdowns recorded" };

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
  const ids = basketIds();
  if (ids.length < 2) return say("Put two or more runs in the basket (tick them in the list) to compare them.", "error");
  const result = await call("GET", `/runs/compare?${ids.map((id) => `ids=${id}`).join("&")}`);
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
