// A listed run's cells in History's table, each built from the API's values as text: how it
// ended (an e-stop, a fall, a lost link, an error stand out as badges), how it was driven, and
// its jumps counted as its kind counts them.
import { element, attributes } from "./dom.js";
import { drawWorld, svgElement } from "./world_draw.js";
import { cachedWorld, worldById } from "./world_list.js";

// End reasons a robot run records (backend/robot/live_run.py) that need a look: a badge each.
const ALARMS = [
  ["e-stop", "e-stop", "estop"],
  ["robot disarmed (fell or timed out)", "fell", "fall"],
  ["fell", "fell", "fall"],
  ["robot restarted", "restarted", "fall"],
  ["robot disarmed itself", "disarmed itself", "fall"],
  ["tracker silent", "tracker silent", "link"],
  ["tracker lost the body", "body lost", "link"],
  ["link lost", "link lost", "link"],
  ["error", "error", "error"],
  ["interrupted", "interrupted", "interrupted"],
];

// The end reason as a badge (title: the reason in full), or as plain text for a clean ending.
export function endingBadge(reason) {
  if (!reason) return element("span", "—");
  for (const [match, words, kind] of ALARMS) {
    if (reason === match || reason.startsWith(`${match}:`)) {
      return attributes(element("span", words), { class: `badge badge-${kind}`, title: reason });
    }
  }
  return attributes(element("span", reason), { class: "ending" });
}

export function statusCell(run) {
  const cell = element("td", run.status);
  cell.className = `col-status status-${run.status}`;
  return cell;
}

// Jumps as the run's kind counts them. A simulation: jumps completed of those asked for. A robot
// or replay run asks for touchdowns (live_run: it ends when it has recorded ``jumps`` of them)
// and measures the jumps between them, one fewer: it shows touchdowns of those asked for, so a
// run that did all 15 reads 15/15, not 14/15.
export function jumpsCell(run) {
  const recorded = run.touchdowns !== null && run.touchdowns !== undefined;
  const cell = element("td", recorded ? `${run.touchdowns}/${run.jumps}` : `${run.jumps_completed}/${run.jumps}`);
  cell.className = "col-jumps";
  cell.title = recorded
    ? `${run.touchdowns} touchdowns recorded of ${run.jumps} asked for; ${run.jumps_completed} jumps measured between them`
    : `${run.jumps_completed} jumps completed of ${run.jumps} asked for`;
  return cell;
}

export const controlsText = (run) => run.controls.map((c) => `${c[0]}°/${c[1]}`).join(", ");
export const targetText = (run) => (run.target === null || run.target === undefined ? "—" : `${run.target}`);

// A cell of column ``name`` (the class that shows or hides it: ``col-NAME``) holding ``text``.
export function cell(name, text, ...children) {
  return attributes(element("td", text, ...children), { class: `col-${name}` });
}

// The run's world: a thumbnail of it (world_draw.js; the worlds fetched once, world_list.js) and
// its name; "parallel walls" for none.
export function worldCell(run) {
  if (!run.world_id) return attributes(cell("world", "parallel"), { title: "parallel walls (no stored world)" });
  const thumb = svgElement("svg", { "aria-hidden": "true", class: "world-thumb" });
  const name = attributes(element("span", `#${run.world_id}`), { class: "world-name" });
  const td = attributes(cell("world", null, thumb, name), { "data-world": run.world_id });
  const show = (world) => {
    drawWorld(thumb, world.world, { thumbnail: true, width: 28, height: 44 });
    name.textContent = world.name;
    td.title = `world #${world.id}: ${world.name} (${world.source})`;
  };
  const known = cachedWorld(run.world_id);
  if (known) show(known);
  else worldById(run.world_id).then(show).catch(() => {});
  return td;
}
