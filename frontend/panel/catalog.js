// What the service offers, from its catalog (GET /api/v1/catalog): the registered controllers
// fill every chooser marked data-controllers — "all" (every one chosen), a name (that one
// chosen) or "none" (nothing chosen: a filter whose first option is "any"); the job kinds fill
// the Jobs tab's chooser (jobs.js). Nothing is listed in the page itself, so a controller or a
// job kind added to a registry shows up everywhere at once.
import { call } from "./api.js";
import { attributes, element } from "./dom.js";

// A line colour per controller, by its place in the registry: the first four as they always were.
const PALETTE = ["#d61f1f", "#e08a00", "#2c6fb7", "#2a9d4b", "#8e44ad", "#8c564b", "#17becf", "#7f7f7f"];
let catalog = null;

// The catalog, asked once (later callers share the same answer).
export function loadCatalog() {
  catalog ??= call("GET", "/catalog").catch((error) => { catalog = null; throw error; });
  return catalog;
}

export async function controllerColor(name) {
  const names = (await loadCatalog()).controllers.map((law) => law.name);
  const at = names.indexOf(name);
  return at < 0 ? "#555" : PALETTE[at % PALETTE.length];
}

function option(law, chosen) {
  const node = attributes(element("option", `${law.name}: ${law.summary}`), { value: law.name });
  node.selected = chosen;
  return node;
}

// Every chooser marked data-controllers, filled from the catalog; a chooser's "any" option stays first.
export async function fillChoosers(root = document) {
  const { controllers } = await loadCatalog();
  for (const select of root.querySelectorAll("select[data-controllers]")) {
    const chosen = select.dataset.controllers;
    const keep = [...select.options].filter((node) => node.value === "");
    select.replaceChildren(...keep, ...controllers.map((law) => option(law, chosen === "all" || chosen === law.name)));
    if (select.multiple) select.size = Math.min(Math.max(controllers.length, 2), 8);
  }
}
