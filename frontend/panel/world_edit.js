// The World tab's editor: a stored world drawn (world_draw.js), its vertices dragged, footholds
// added and removed, a segment's friction set, or its §8 JSON edited in the text box; "Save as new
// world" posts the edit as a new world (a stored world is the record of the runs in it, so it
// never changes under them). A 422 is shown at the segment its loc names (world.left.points[2]).
import { $, say, call, on } from "./api.js";
import { element } from "./dom.js";
import { drawWorld, drawLegend, muWords } from "./world_draw.js";
import { loadWorlds } from "./world_list.js";

const HOLD = { l0: 0.3, m: 0.067 };  // a new foothold's length (about 0.3 l0 of the paper's robot)
const HOLD_BETA = 20 * Math.PI / 180;  // facing upward, as the staircase's steps
const DIGITS = 1e4;  // a dragged vertex's coordinates, rounded to 1e-4 of the document's unit
const state = { stored: null, doc: null, selected: null, error: null, frame: null, drag: null };
let opened = () => {};  // what the tab does with a world just stored (worlds.js: list it, open it)

export const onStored = (handler) => { opened = handler; };
const clone = (value) => JSON.parse(JSON.stringify(value));

// The world file as text: a point a line, as `parkour world show --json` and save_world write it.
// An array of numbers (a point, a side's mu) on one line.
export const worldText = (doc) => JSON.stringify(doc, null, 2)
  .replace(/\[([^[\]{}"]*(?:"inf"[^[\]{}"]*)*)\]/g, (_, inner) => `[${inner.trim().split(/\s*,\s*/).join(", ")}]`);

// Open ``stored`` (a WorldOut) in the editor; ``draft``: an unsaved document to show in its place.
export function openWorld(stored, draft = null) {
  state.stored = stored;
  state.doc = clone(draft ?? stored.world);
  state.selected = state.error = state.frame = state.drag = null;
  $("#world-editor").hidden = false;
  $("#world-title").textContent = stored.id ? `World #${stored.id}: ${stored.name}` : `New world: ${stored.name}`;
  $("#world-rename-form").hidden = $("#world-delete").hidden = !stored.id;
  $("#world-rename-form").elements.name.value = stored.name;
  $("#world-about").textContent = stored.id
    ? `${stored.source}; used by ${stored.runs} run(s) and ${stored.jobs} job(s); in ${stored.world.units ?? "?"}.`
    : "Not stored: the service refused it (marked below). Fix it and save.";
  $("#world-save-form").elements.name.value = stored.id ? `${stored.name} (edited)` : stored.name;
  $("#world-errors").replaceChildren();
  render(true);
}

function render(withText = false) {
  state.drawn = drawWorld($("#world-svg"), state.doc, { selected: state.selected, error: state.error, frame: state.frame ?? undefined });
  if (withText) $("#world-json").value = worldText(state.doc);
  showSelection();
}

// An edit of the drawing: the marks of the last refusal go (the list of them stays until the next save).
function edited() {
  state.error = null;
  render(true);
}

function showSelection() {
  const chosen = state.selected, form = $("#world-segment-form");
  form.hidden = !chosen || chosen.vertex;
  if (!chosen) {
    $("#world-selected").textContent = "Click a segment to set its friction or add a foothold on it; drag a vertex to move it.";
    return;
  }
  const side = state.doc[chosen.side];
  if (chosen.vertex) {
    const [x, y] = side.points[chosen.index] ?? [NaN, NaN];
    $("#world-selected").textContent = `${chosen.side} point ${chosen.index}: (${x}, ${y})`;
    return;
  }
  const mu = Array.isArray(side.mu) ? side.mu[chosen.index] ?? null : null;
  $("#world-selected").textContent = `${chosen.side} segment ${chosen.index}: mu ${muWords(mu)}`;
  form.elements.mu.value = mu === null ? "" : String(mu);
}

// Pointer: a vertex is chosen and dragged (the drawing's frame held while it moves), a segment chosen.
on("#world-svg", "pointerdown", (event) => {
  const target = event.target.closest(".world-vertex, .world-segment");
  if (!target || !state.doc) return;
  const pick = { side: target.dataset.side, index: Number(target.dataset.index), vertex: target.classList.contains("world-vertex") };
  state.selected = pick;
  if (pick.vertex) {
    state.drag = pick;
    state.frame = state.drawn.frame;
    $("#world-svg").setPointerCapture(event.pointerId);
    event.preventDefault();
  }
  render();
});
on("#world-svg", "pointermove", (event) => {
  if (!state.drag) return;
  const [x, y] = state.drawn.toWorld(event.clientX, event.clientY);
  state.doc[state.drag.side].points[state.drag.index] = [Math.round(x * DIGITS) / DIGITS, Math.round(y * DIGITS) / DIGITS];
  render();
});
const endDrag = () => {
  if (!state.drag) return;
  state.drag = state.frame = null;
  edited();
};
on("#world-svg", "pointerup", endDrag);
on("#world-svg", "pointercancel", endDrag);

// A side's mu list, written out (one entry per segment, null: the model's) before it is edited.
function muOf(name) {
  const side = state.doc[name];
  if (!Array.isArray(side.mu)) side.mu = Array(Math.max(side.points.length - 1, 0)).fill(null);
  return side.mu;
}

// "" or null: the model's mu; inf: no slip; a number. Anything else: undefined.
function muEntry(text) {
  const value = text.trim().toLowerCase();
  if (value === "" || value === "null") return null;
  if (value === "inf") return "inf";
  return value !== "" && Number.isFinite(Number(value)) ? Number(value) : undefined;
}

on("#world-segment-form", "submit", (event) => {
  event.preventDefault();
  const { side, index } = state.selected;
  const entry = muEntry(event.target.elements.mu.value);
  if (entry === undefined) return say("mu: a number, inf (no slip) or empty (the model's mu)", "error");
  muOf(side)[index] = entry;
  edited();
});

// A foothold in the middle of the chosen segment: 0.3 l0 long facing 20° upward, the model's mu,
// the segment's two ends keeping its friction.
on("#world-add-hold", "click", () => {
  const { side, index } = state.selected;
  const points = state.doc[side].points, mu = muOf(side);
  const [a, b] = [points[index], points[index + 1]];
  const length = Math.min(HOLD[state.doc.units] ?? HOLD.l0, 0.5 * Math.hypot(b[0] - a[0], b[1] - a[1]));
  const t = [(side === "left" ? -1 : 1) * Math.sin(HOLD_BETA), Math.cos(HOLD_BETA)];  // along it, upward
  const middle = [(a[0] + b[0]) / 2, (a[1] + b[1]) / 2];
  const ends = [-0.5, 0.5].map((f) => middle.map((v, i) => Math.round((v + f * length * t[i]) * DIGITS) / DIGITS));
  if (!(ends[0][1] > a[1] && ends[1][1] < b[1])) return say("This segment is too short or too flat for a foothold: choose a longer one.", "error");
  points.splice(index + 1, 0, ...ends);
  mu.splice(index + 1, 0, null, mu[index]);
  state.selected = { side, index: index + 1, vertex: false };
  edited();
  say(`A foothold added on the ${side} side (segment ${index + 1}): 20° upward, the model's mu.`);
});

// The chosen segment removed: its inner ends go, and the segments beside it join, with the
// friction of the one below it (the one above, at the bottom).
on("#world-remove-hold", "click", () => {
  const { side, index } = state.selected;
  const points = state.doc[side].points, mu = muOf(side), last = points.length - 1;
  if (last < 2) return say("A side keeps at least one segment.", "error");
  const drop = [index, index + 1].filter((k) => k > 0 && k < last);
  const low = drop.includes(index) ? index - 1 : index, high = drop.includes(index + 1) ? index + 1 : index;
  const kept = index > 0 ? mu[index - 1] : mu[index + 1];
  state.doc[side].points = points.filter((_, k) => !drop.includes(k));
  state.doc[side].mu = [...mu.slice(0, low), kept ?? null, ...mu.slice(high + 1)];
  state.selected = null;
  edited();
});

on("#world-apply", "click", () => {
  try {
    state.doc = JSON.parse($("#world-json").value);
  } catch (error) {
    return say(`The world file is not JSON: ${error.message}`, "error");
  }
  state.selected = state.error = null;
  render();
});
on("#world-reset", "click", () => openWorld(state.stored));

// A 422's errors: each in the list, the first that names a side's point or segment at it.
const LOC = /^world\.(left|right)(?:\.(points|mu)\[(\d+)\])?/;
export function showErrors(detail) {
  const errors = Array.isArray(detail) ? detail : [{ loc: [], msg: String(detail) }];
  state.error = null;
  const items = errors.map((error) => {
    const where = (error.loc || []).filter((part) => part !== "body").join(".");
    // The service's words may repeat where ("world.left.points[2]: y must…"): said once.
    const message = String(error.msg).replace(/^(Value|Assertion) error, /, "").replace(`${where}: `, "");
    const found = LOC.exec(where);
    if (found && !state.error) {
      state.error = { side: found[1], index: Number(found[3] ?? 0), vertex: found[2] !== "mu", message };
      state.selected = null;
    }
    return element("li", where ? `${where}: ${message}` : message);
  });
  $("#world-errors").replaceChildren(...items);
  render();
}

on("#world-save-form", "submit", async (event) => {
  event.preventDefault();
  const name = event.target.elements.name.value.trim();
  try {
    state.doc = JSON.parse($("#world-json").value);
  } catch (error) {
    return say(`The world file is not JSON: ${error.message}`, "error");
  }
  let world;
  try {
    world = await call("POST", "/worlds", { name, world: state.doc },
      { form: event.target, locations: { name: "name" }, action: "Save as new world" });
  } catch (error) {
    if (error.status === 422) showErrors(error.detail);
    throw error;
  }
  say(`World #${world.id} "${world.name}" stored.`);
  await loadWorlds(true);
  opened(world);
});

drawLegend($("#world-legend"));
