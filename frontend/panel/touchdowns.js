// Predicted against measured: a robot or replay run's touchdowns (History → "touchdowns") beside
// the paper's model's one-jump prediction of each and, with a stored calibration chosen, the
// calibrated model's; one channel at a time (xdot, ydot, rise), the residuals below, the RMS of
// each model as text. A failed prediction (null) is left out of the plots, never drawn as 0.
// A run in a stored world is predicted by each model's jump in that world (comparison.world):
// the caption names it, the legend says "in world N" (its id only: Plotly reads a name's tags).
import { $, call, on } from "./api.js";
import { PLOT_CONFIG, layout } from "./plots.js";
import { number } from "./calibration.js";

const CHANNELS = {
  xdot: { words: "xdot at the section", unit: "√(g l0)" },
  ydot: { words: "ydot at the section", unit: "√(g l0)" },
  rise: { words: "rise since the touchdown before", unit: "l0" },
};
const COLOURS = { measured: "#1d2733", paper: "#2c6fb7", calibrated: "#e07b00" };
const shown = { runId: null, comparison: null, asked: 0 };  // asked: the latest call's number (an older answer is dropped)

// The touchdowns' index and value of ``channel`` in ``pick(touchdown)``, nulls (and a missing model) left out.
function series(touchdowns, pick, channel) {
  const kept = touchdowns.filter((td) => pick(td) && pick(td)[channel] !== null && pick(td)[channel] !== undefined);
  return { x: kept.map((td) => td.index), y: kept.map((td) => pick(td)[channel]) };
}

// " in world N" when the run climbed a stored world (its predictions are jumps there), else "".
const inWorld = (comparison) => (comparison.world ? ` in world ${Number(comparison.world.id)}` : "");

function rmsText(comparison) {
  const models = Object.entries(comparison.rms);
  if (!models.length) return "No touchdown pairs to compare.";
  const described = models.map(([model, rms]) => {
    const name = (model === "calibrated" ? `calibrated (${comparison.preset})` : model) + inWorld(comparison);
    const parts = Object.keys(CHANNELS).map((channel) => `${channel} ${number(rms[channel])} ${CHANNELS[channel].unit}`);
    return `${name}: ${parts.join(", ")}`;
  });
  return `RMS residual over ${comparison.touchdowns.length} touchdowns — ${described.join("; ")}.`;
}

function draw() {
  const comparison = shown.comparison;
  if (!comparison) return;
  const channel = $("#touchdown-channel").value;
  const { words, unit } = CHANNELS[channel];
  const tds = comparison.touchdowns;
  const models = [["paper", (td) => td.paper, (td) => td.paper_residual]];
  if (comparison.preset) models.push(["calibrated", (td) => td.calibrated, (td) => td.calibrated_residual]);
  const label = (model) => (model === "calibrated" ? `calibrated (${comparison.preset})` : `${model}'s model`)
    + inWorld(comparison);
  const values = [{ ...series(tds, (td) => td.measured, channel), mode: "markers", name: "measured", marker: { color: COLOURS.measured, size: 7 } },
    ...models.map(([model, pick]) => ({ ...series(tds, pick, channel), mode: "lines+markers", name: label(model),
      line: { color: COLOURS[model] }, marker: { color: COLOURS[model], size: 5, symbol: "x" } }))];
  const residuals = models.map(([model, , pick]) => ({ ...series(tds, pick, channel), mode: "lines+markers", name: label(model),
    line: { color: COLOURS[model] }, marker: { color: COLOURS[model], size: 5 } }));
  const zero = { type: "line", xref: "paper", x0: 0, x1: 1, y0: 0, y1: 0, line: { color: "#888", dash: "dot", width: 1 } };
  const legend = { legend: { orientation: "h", y: -0.25 }, margin: { l: 60, r: 15, t: 40, b: 90 } };
  Plotly.react("touchdown-plot", values, layout(`Run ${comparison.run_id}: ${words}, measured and predicted${inWorld(comparison)}`,
    "touchdown (its number in the run)", `${channel} [${unit}]`, legend), PLOT_CONFIG);
  Plotly.react("residual-plot", residuals, layout("Residual: predicted − measured", "touchdown (its number in the run)",
    `${channel} residual [${unit}]`, { ...legend, shapes: [zero] }), PLOT_CONFIG);
}

export async function showTouchdowns(runId) {
  const preset = $("#touchdown-preset").value;
  const query = preset ? `?preset=${encodeURIComponent(preset)}` : "";
  const box = $("#touchdowns-box");
  $("#touchdowns-rms").textContent = `Predicting run ${runId}'s touchdowns…`;
  box.hidden = false;
  const asked = ++shown.asked;
  let comparison;
  try {
    comparison = await call("GET", `/runs/${runId}/touchdowns${query}`);
  } catch (error) {
    if (asked === shown.asked) $("#touchdowns-rms").textContent = `Run ${runId}: ${error.message}`;
    throw error;
  }
  if (asked !== shown.asked) return comparison;  // another run or model was asked for since
  Object.assign(shown, { runId, comparison });
  const world = comparison.world;
  $("#touchdowns-title").textContent = `Touchdowns of run ${comparison.run_id}: measured against the ${comparison.base} model`
    + `${comparison.preset ? ` and calibration ${comparison.preset}` : ""}`
    + (world ? `, each predicted by a jump in world ${world.id} (${world.name}), not between parallel walls` : "");
  $("#touchdowns-rms").textContent = rmsText(comparison);
  draw();
  return comparison;
}

on("#run-table", "click", async (event) => {
  const button = event.target.closest("button.show-touchdowns");
  if (!button) return;
  await showTouchdowns(Number(button.dataset.run));
  $("#touchdowns-box").scrollIntoView({ block: "start" });
});
on("#touchdown-channel", "change", draw);  // the same touchdowns, another channel: no call
on("#touchdown-preset", "change", async () => { if (shown.runId !== null) await showTouchdowns(shown.runId); });
