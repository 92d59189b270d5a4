// History's experiments: the list (create one; every form's "in experiment" choice), and an
// experiment's page (GET /api/v1/experiments/{id}/summary): its description and notes, its runs'
// outcomes over all and by kind (mean ± std, the mean's 95% interval), how they ended, and its
// jobs, each with a Show that opens it in the Jobs tab. Every value reaches the page as text.
import { $, say, call, on } from "./api.js";
import { selectTab } from "./tabs.js";
import { describeJob, showJob } from "./jobs.js";
import { element, fillTable, attributes } from "./dom.js";
import { endingBadge } from "./run_cells.js";

let showRuns = () => {};  // history.js: list the runs of an experiment (id) or of every one (null)
export function onExperimentRuns(callback) { showRuns = callback; }

export async function loadExperiments() {
  const page = await call("GET", "/experiments?limit=100");
  const filter = $("#experiment-filter");
  const chosen = filter.value;
  filter.replaceChildren(new Option("any", ""), ...page.items.map((e) => new Option(`${e.id}: ${e.name}`, String(e.id))));
  filter.value = page.items.some((e) => String(e.id) === chosen) ? chosen : "";
  for (const choice of document.querySelectorAll("select.experiment-choice")) {
    const kept = choice.value;
    choice.replaceChildren(new Option("none", ""), ...page.items.map((e) => new Option(`${e.id}: ${e.name}`, String(e.id))));
    choice.value = page.items.some((e) => String(e.id) === kept) ? kept : "";
  }
  fillTable("#experiment-table", page.items.map((experiment) => element("tr", null,
    element("td", String(experiment.id)),
    element("td", null, attributes(element("button", experiment.name), { type: "button", class: "show-experiment", "data-experiment": experiment.id })),
    attributes(element("td", experiment.description), { class: "description" }), element("td", String(experiment.runs)),
    attributes(element("td", experiment.tags.join(" ")), { class: "tags" }), element("td", new Date(experiment.created_at).toLocaleString()))),
    "No experiments yet: name one above.");
}

loadExperiments().catch(() => {});  // the forms' "in experiment" choices, from the start

on("#experiment-table", "click", async (event) => {
  const button = event.target.closest("button.show-experiment");
  if (!button) return;
  await Promise.all([showRuns(button.dataset.experiment), showExperiment(button.dataset.experiment)]);
});

on("#experiment-form", "submit", async (event) => {
  event.preventDefault();
  const form = new FormData(event.target);
  const experiment = await call("POST", "/experiments", { name: String(form.get("name")), description: String(form.get("description")) });
  event.target.reset();
  await loadExperiments();
  say(`Experiment ${experiment.id} "${experiment.name}" created; runs and jobs join it through experiment_id.`);
});

const digits = (value, count = 4) => (value === null || value === undefined ? "—" : String(Number(Number(value).toPrecision(count))));
const meanStd = (stats) => `${digits(stats.mean)} ± ${digits(stats.std, 3)}`;
const interval = (stats) => (stats.ci95_low === null ? "— (one run)" : `${digits(stats.ci95_low)} … ${digits(stats.ci95_high)}`);
const counted = (counts) => Object.entries(counts).map(([name, count]) => `${count} ${name}`).join(", ");

function outcomeRow(label, group) {
  return element("tr", null, element("td", label), element("td", String(group.runs)),
    element("td", meanStd(group.climb)), attributes(element("td", interval(group.climb)), { class: "ci" }),
    element("td", meanStd(group.jumps_completed)), attributes(element("td", interval(group.jumps_completed)), { class: "ci" }));
}

function jobRow(job) {
  const progress = attributes(element("progress", null), { max: 1, value: job.progress, "aria-label": `job ${job.id} progress` });
  const show = attributes(element("button", "Show"), { type: "button", class: "show-job", "data-job": job.id,
    "aria-label": `show job ${job.id} in the Jobs tab` });
  return element("tr", null, element("td", String(job.id)), element("td", job.kind), attributes(element("td", describeJob(job)), { class: "what" }),
    element("td", job.state), element("td", null, progress, ` ${job.completed}/${job.total}`), element("td", null, show));
}

let shown = 0;  // the page asked for last: an older answer arriving later is not shown

// Experiment ``id``'s page (its runs are History's list, filtered to it).
export async function showExperiment(id) {
  const mine = ++shown;
  const summary = await call("GET", `/experiments/${id}/summary`);
  if (mine !== shown) return summary;
  const { experiment } = summary;
  $("#experiment-title").textContent = `Experiment ${experiment.id}: ${experiment.name}`;
  $("#experiment-description").textContent = experiment.description;
  $("#experiment-description").hidden = !experiment.description;
  $("#experiment-notes").replaceChildren(...(experiment.notes ? [element("strong", "Notes: "), experiment.notes] : []));
  $("#experiment-notes").hidden = !experiment.notes;
  const endings = Object.entries(summary.end_reasons);
  $("#experiment-counts").replaceChildren(
    `${summary.runs} run${summary.runs === 1 ? "" : "s"}${summary.runs ? `: ${counted(summary.statuses)}; loop ${counted(summary.loops)}` : ""}`,
    ...(endings.length ? ["; robot runs ended: ", ...endings.flatMap(([reason, count], k) =>
      [...(k ? [", "] : []), `${count} × `, endingBadge(reason)])] : []), ".");
  fillTable("#experiment-outcomes", summary.outcomes
    ? [outcomeRow("all", summary.outcomes), ...summary.by_kind.map((group) => outcomeRow(String(group.key), group))] : [],
  "No runs in it yet.");
  const more = summary.jobs_total > summary.jobs.length ? ` (the newest ${summary.jobs.length} of ${summary.jobs_total})` : "";
  $("#experiment-jobs caption").textContent = `Jobs in experiment ${experiment.id}: ${experiment.name}${more}`;
  fillTable("#experiment-jobs", summary.jobs.map(jobRow), "No jobs in this experiment.");
  $("#experiment-jobs").hidden = false;
  $("#experiment-page").hidden = false;
  return summary;
}

export function closeExperiment() {
  shown += 1;
  $("#experiment-page").hidden = $("#experiment-jobs").hidden = true;
}

on("#experiment-close", "click", () => { closeExperiment(); return showRuns(null); });

// Show: the job in the Jobs tab, drawn as that tab's own Show draws it, whichever of its pages
// the job is on.
on("#experiment-jobs", "click", async (event) => {
  const button = event.target.closest("button.show-job");
  if (!button) return;
  selectTab("jobs");
  await showJob(button.dataset.job);
  $("#job-plot").scrollIntoView({ block: "nearest" });
});
