// The World tab: the stored worlds (name, where each came from, when and by whom, how many runs
// and jobs use it), a world made from a named one, a seed or pasted §8 JSON, and the one chosen
// opened in the editor (world_edit.js) to draw, edit, save as new, rename or delete.
import { $, say, call, on } from "./api.js";
import { Fields } from "./fields.js";
import { attributes, element, fillTable } from "./dom.js";
import { svgElement, drawWorld } from "./world_draw.js";
import { loadWorlds } from "./world_list.js";
import { openWorld, onStored, showErrors } from "./world_edit.js";

const form = () => $("#world-create-form");
let current = null;  // the world open in the editor (its id), kept open when the list is shown again

function worldRow(world) {
  const thumb = svgElement("svg", { "aria-hidden": "true" });
  drawWorld(thumb, world.world, { thumbnail: true, width: 28, height: 44 });
  const moment = new Date(world.created_at);
  const open = attributes(element("button", world.name), { type: "button", class: "link open-world", "data-world": world.id,
    "aria-label": `open world ${world.id}, ${world.name}` });
  const row = element("tr", null, element("td", null, thumb), element("td", String(world.id)), element("td", null, open),
    element("td", world.source), attributes(element("td", moment.toLocaleDateString()),
      { title: `${moment.toLocaleString()}${world.created_by ? ` by ${world.created_by}` : ""}` }),
    element("td", String(world.runs)), element("td", String(world.jobs)));
  row.id = `world-${world.id}`;
  if (world.id === current) row.classList.add("chosen");
  return row;
}

// The list, fetched again; the world open in the editor stays open (a stale one closes).
export async function loadWorldTab() {
  const worlds = await loadWorlds(true);
  fillTable("#world-table", worlds.map(worldRow), "No worlds stored yet: make one with the form above.");
  $("#world-count").textContent = `${worlds.length} stored`;
  if (current !== null && !worlds.some((world) => world.id === current)) {
    current = null;
    $("#world-editor").hidden = true;
  }
}

function show(world) {
  current = world.id;
  for (const row of document.querySelectorAll("#world-table tbody tr")) row.classList.toggle("chosen", row.id === `world-${world.id}`);
  openWorld(world);
}

on("#world-table", "click", async (event) => {
  const button = event.target.closest("button.open-world");
  if (!button) return;
  show(await call("GET", `/worlds/${button.dataset.world}`));
});

onStored(async (world) => {
  await loadWorldTab();
  show(world);
});

// The create form: the fields of the chosen source only.
function showSource() {
  const source = form().elements.source.value;
  for (const label of form().querySelectorAll("[data-source]")) label.hidden = label.dataset.source !== source;
}
on("#world-source", "change", showSource);

async function fillNamed() {
  const named = (await Fields.annotation("WorldCreate.named", "x-named-worlds")) ?? [];
  $("#world-named").replaceChildren(...named.map((world) => attributes(new Option(world.name, world.name), { title: world.description })));
}
fillNamed().catch(() => {});

on("#world-create-form", "submit", async (event) => {
  event.preventDefault();
  const fields = form().elements, source = fields.source.value;
  let body, name = fields.name.value.trim();
  if (source === "named") body = { named: fields.named.value };
  if (source === "random") {
    const values = await Fields.readFields(form(), [{ name: "seed", rule: "RandomWorldIn.seed" },
      { name: "holds", rule: "RandomWorldIn.holds", optional: true }]);
    if (values === null) return say("Fix the marked field(s) first: nothing was sent.", "error");
    body = { random: { seed: values.seed, ...(values.holds === null || values.holds === undefined ? {} : { holds: values.holds }) } };
  }
  if (source === "json") {
    try {
      body = { world: JSON.parse(fields.json.value) };
    } catch (error) {
      return say(`The world file is not JSON: ${error.message}`, "error");
    }
  }
  name ||= body.named ?? body.world?.name ?? (body.random ? `random ${body.random.seed}` : "");
  const at = { form: form(), locations: { name: "name", named: "named", "random.seed": "seed", "random.holds": "holds" }, action: "Create world" };
  let world;
  try {
    world = await call("POST", "/worlds", { name, ...body }, at);
  } catch (error) {
    if (error.status === 422 && body.world) {  // refused JSON: drawn in the editor, marked at its segment
      current = null;
      openWorld({ id: null, name, world: body.world, source: "posted", runs: 0, jobs: 0 });
      showErrors(error.detail);
    }
    throw error;
  }
  say(`World #${world.id} "${world.name}" stored (${world.source}).`);
  await loadWorldTab();
  show(world);
});

on("#world-rename-form", "submit", async (event) => {
  event.preventDefault();
  const name = event.target.elements.name.value.trim();
  const world = await call("PATCH", `/worlds/${current}`, { name }, { form: event.target, locations: { name: "name" }, action: "Rename" });
  say(`World #${world.id} is now "${world.name}".`);
  await loadWorldTab();
  show(world);
});

// Delete: refused (409, the API's message naming a run or job) while a run or job uses the world.
on("#world-delete", "click", async () => {
  const id = current;
  await call("DELETE", `/worlds/${id}`, undefined, { action: `Delete world #${id}` });
  say(`World #${id} deleted.`);
  current = null;
  $("#world-editor").hidden = true;
  await loadWorldTab();
});

showSource();
