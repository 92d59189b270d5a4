// A controller's MFPT job in the Jobs tab (the result of ``parkour mfpt --controller --json``:
// backend/jobs/loop_mfpt.py): the estimate in words, and each splitting run's failure
// probability (an exit failing before it comes home) around their mean. Every value reaches the
// page as text or as Plotly data.
import { $ } from "./api.js";
import { draw, layout } from "./plots.js";

const SUMMARY = "#job-summary";

export function hideLoopMfpt() {
  const summary = $(SUMMARY);
  summary.hidden = true;
  summary.textContent = "";
}

const jumps = (value) => (value >= 1e5 ? value.toExponential(2) : Math.round(value).toLocaleString("en"));
const probability = (value) => (value === 0 ? "0" : value.toPrecision(3));
const meanOf = (values) => values.reduce((sum, value) => sum + value, 0) / values.length;

// The estimate as a sentence: "lqr holds 0.55 m for about 234 jumps (95%: 116–486), by splitting; λ₂ …".
export function loopMfptWords(result) {
  const split = result.splitting;
  const how = `${split.runs} runs × ${split.replicas} replicas, seed ${split.seed}, ${result.seconds.toFixed(1)} s`;
  if (result.mfpt_jumps === null) {
    const bound = typeof result.mfpt_at_least_jumps === "number"
      ? ` — more than ${jumps(result.mfpt_at_least_jumps)} jumps (95%: no failure in the ${result.failure_free_jumps} jumps its long runs held)` : "";
    return `${result.controller} holds ${result.target_m} m past anything splitting reached${bound}: no run saw an exit fail (${how}).`;
  }
  const interval = result.ci95 ? ` (95%: ${jumps(result.ci95[0])}–${jumps(result.ci95[1])})` : "";
  return `${result.controller} holds ${result.target_m} m for about ${jumps(result.mfpt_jumps)} jumps${interval}, by splitting; ` +
    `λ₂ ${result.lambda2.toFixed(6)} (1/(1−λ₂) ${jumps(result.lambda2_jumps)} jumps from holding), ` +
    `an exit fails with p ${probability(meanOf(split.probabilities))} on average, a loop back home every ` +
    `${meanOf(split.loop_jumps).toFixed(1)} jumps; ${how}.`;
}

export function showLoopMfpt(id, result) {
  const words = loopMfptWords(result);
  const summary = $(SUMMARY);
  summary.textContent = `Job ${id}: ${words}`;
  summary.hidden = false;  // aria-live: read out as it appears
  const { probabilities } = result.splitting;
  const mean = meanOf(probabilities);
  const runs = probabilities.map((_, i) => i + 1);
  const logScale = probabilities.every((p) => p > 0);  // a run with no failure (p = 0) has no place on a log axis
  const meanLine = { type: "line", xref: "paper", x0: 0, x1: 1, y0: mean, y1: mean, line: { color: "#888", dash: "dash" } };
  draw("job-plot", [
    { x: runs, y: probabilities, mode: "markers", name: "a run's p", marker: { size: 8, color: "#2c6fb7" },
      hovertemplate: "run %{x}: p = %{y:.3g}<extra></extra>" },
  ], layout(`Job ${id}: ${result.controller} at ${result.target_m} m, each splitting run's failure probability (dashed: their mean)`,
    "splitting run", "p: an exit fails before it comes home", {
      height: 340, shapes: mean > 0 || !logScale ? [meanLine] : [],
      xaxis: { title: { text: "splitting run" }, dtick: runs.length <= 20 ? 1 : undefined },
      yaxis: { title: { text: "p: an exit fails before home" }, type: logScale ? "log" : "linear", exponentformat: "power" },
    }));
}
