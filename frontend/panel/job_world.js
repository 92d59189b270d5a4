// Jobs in a stored world (docs/service.md, "Jobs in worlds"): the parts of a job form built from
// its request's schema (job_forms.js) that are no plain number — the world chooser (world_id: a
// stored world by name, from the list world_list.js shares), the foothold study's other source
// (random_worlds: how many and the first seed) and the legs a world-mjtf job climbs with
// (controls: a psi0 and a zeta0 per leg, in turn, as the MJTF form's lists). Each value is
// checked against the API's own ranges (fields.js); a 422 lands at the field that sent it.
import { say } from "./api.js";
import { Fields } from "./fields.js";
import { attributes, element } from "./dom.js";
import { fillWorldChoosers, loadWorlds } from "./world_list.js";

// The properties made here; ``controls`` only with a world (a gait search's legs stay the API's).
export const WORLD_PARTS = new Set(["world_id", "random_worlds", "controls"]);
const MAX_LEGS = 64;  // the API's most legs (WorldMjtfJobCreate.controls)

const labelled = (words, input, title) => {
  const label = element("label", `${words} `, input);
  if (title) label.title = title;
  return label;
};
const numberInput = (name, value, step = "1") => attributes(element("input", null), { name, type: "number", step, value });

// The world chooser, filled from the shared list (and again whenever it changes).
function worldChooser(name) {
  const select = attributes(element("select", null, new Option("choose a stored world", "")), { name, "data-worlds": "" });
  loadWorlds().then((worlds) => fillWorldChoosers(worlds, [select])).catch(() => {});
  return select;
}

// The elements and the behaviour of ``kind``'s world parts (``names``: the properties of its
// request among WORLD_PARTS), or null when the panel cannot build them (legs without a world).
export function worldPart(kind, names) {
  const has = (name) => names.includes(name);
  if (!has("world_id")) return null;
  const at = (name) => `${kind}__${name}`;
  const nodes = [];
  const random = has("random_worlds");
  if (random) {  // the foothold study: a stored world or random ones
    const source = attributes(element("select", null, new Option("a stored world", "world"), new Option("random worlds", "random")),
      { name: at("source") });
    nodes.push(labelled("worlds", source));
    source.addEventListener("change", () => showSource(source));
  }
  nodes.push(attributes(labelled("world", worldChooser(at("world_id")), "a stored world (the World tab makes and draws them)"),
    { "data-world-source": "world" }));
  if (random) {
    nodes.push(attributes(labelled("how many", numberInput(at("random_count"), "5"), "random-foothold worlds, drawn from seeds"),
      { "data-world-source": "random", hidden: "" }),
    attributes(labelled("first seed", numberInput(at("random_seed0"), "0"), "the first world's seed; the next ones follow"),
      { "data-world-source": "random", hidden: "" }));
  }
  const legs = has("controls");
  if (legs) {
    nodes.push(labelled("legs psi0 [deg]", attributes(element("input", null), { name: at("psi0s"), value: "30", size: 12 }),
      "each leg's psi0, comma-separated; the legs are taken in turn"),
    labelled("zeta0 [l0]", attributes(element("input", null), { name: at("zeta0s"), value: "0.9", size: 12 }),
      "each leg's zeta0, in the same order"));
  }
  return {
    nodes,
    // The fields to check now (the source chosen decides which).
    fields(form) {
      const fromRandom = random && form.elements[at("source")].value === "random";
      return [
        ...(fromRandom ? [{ name: at("random_count"), rule: "RandomWorldsIn.count" }, { name: at("random_seed0"), rule: "RandomWorldsIn.seed0" }] : []),
        ...(legs ? [{ name: at("psi0s"), rule: "LegIn.psi0_deg", unit: "°", list: true }, { name: at("zeta0s"), rule: "LegIn.zeta0", unit: "l0", list: true }] : []),
      ];
    },
    // Whether a world is chosen (else its chooser is marked): checked with the fields, after them.
    chosen(form) {
      if (random && form.elements[at("source")].value === "random") return true;
      if (form.elements[at("world_id")].value !== "") return true;
      Fields.mark(form.elements[at("world_id")], "choose a stored world (the World tab makes one)");
      return false;
    },
    // The body's world (and legs) from the checked values ``v``, or null after marking what is wrong.
    body(form, v) {
      const body = {};
      let ok = true;
      if (random && form.elements[at("source")].value === "random") {
        body.random_worlds = { count: v[at("random_count")], seed0: v[at("random_seed0")] };
      } else {
        body.world_id = Number(form.elements[at("world_id")].value);
      }
      if (legs && v[at("psi0s")] && v[at("zeta0s")]) {
        const [psi0s, zeta0s] = [v[at("psi0s")], v[at("zeta0s")]];
        if (psi0s.length !== zeta0s.length) {
          Fields.mark(form.elements[at("zeta0s")], `give one zeta0 a leg: ${psi0s.length} psi0, ${zeta0s.length} zeta0`);
          ok = false;
        } else if (psi0s.length > MAX_LEGS) {
          Fields.mark(form.elements[at("psi0s")], `at most ${MAX_LEGS} legs`);
          ok = false;
        }
        body.controls = psi0s.map((psi0, i) => ({ psi0_deg: psi0, zeta0: zeta0s[i] }));
      }
      if (!ok) say("Fix the marked field(s) first: nothing was sent.", "error");
      return ok ? body : null;
    },
    // A 422's locations: the body's fields -> the inputs that sent them.
    locations: {
      world_id: at("world_id"), random_worlds: at("random_count"), "random_worlds.count": at("random_count"),
      "random_worlds.seed0": at("random_seed0"), controls: at("psi0s"),
      ...Object.fromEntries([...Array(MAX_LEGS).keys()].flatMap((i) => [[`controls.${i}.psi0_deg`, at("psi0s")], [`controls.${i}.zeta0`, at("zeta0s")]])),
    },
  };
}

// Show the chosen source's fields only (hidden ones are neither checked nor sent).
function showSource(source) {
  for (const label of source.closest("fieldset").querySelectorAll("[data-world-source]")) {
    label.hidden = label.dataset.worldSource !== source.value;
  }
}
