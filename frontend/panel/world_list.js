// The stored worlds (GET /api/v1/worlds), fetched once and shared: the World tab's list, the
// Simulate tab's world chooser, History's world filter and its thumbnails. A change (a world
// created, renamed, deleted) reloads them, and every chooser marked data-worlds is filled again.
import { call } from "./api.js";

const PAGE = 500;  // the API's largest page
let loading = null;
const byId = new Map();
const listeners = [];

// Every stored world, newest first (asked once; ``fresh``: asked again).
export function loadWorlds(fresh = false) {
  if (fresh) loading = null;
  loading ??= (async () => {
    const all = [];
    let cursor = null;
    do {
      const page = await call("GET", `/worlds?limit=${PAGE}${cursor ? `&cursor=${cursor}` : ""}`);
      all.push(...page.items);
      cursor = page.next_cursor;
    } while (cursor);
    byId.clear();
    for (const world of all) byId.set(world.id, world);
    fillWorldChoosers(all);
    listeners.forEach((listener) => listener(all));
    return all;
  })().catch((error) => { loading = null; throw error; });
  return loading;
}

// One world: from the list, else asked for by itself (a world stored since the list was fetched).
const asked = new Map();  // id -> the answer awaited: a page of runs in one new world asks once
export async function worldById(id) {
  await loadWorlds().catch(() => {});
  if (byId.has(id)) return byId.get(id);
  if (!asked.has(id)) asked.set(id, call("GET", `/worlds/${id}`).finally(() => asked.delete(id)));
  const world = await asked.get(id);
  byId.set(id, world);
  return world;
}

export const cachedWorld = (id) => byId.get(id);
export const onWorldsChange = (listener) => listeners.push(listener);

// Every chooser marked data-worlds (or those of ``selects``: one not in the page yet): its
// first option (none, any) kept, then a world a line.
export function fillWorldChoosers(worlds, selects = document.querySelectorAll("select[data-worlds]")) {
  for (const select of selects) {
    const chosen = select.value;
    const keep = [...select.options].filter((node) => node.value === "");
    select.replaceChildren(...keep, ...worlds.map((world) => new Option(`${world.name} (#${world.id})`, String(world.id))));
    if (chosen && !worlds.some((world) => String(world.id) === chosen)) select.append(new Option(`world ${chosen}`, chosen));
    select.value = chosen;
  }
}
