// The ParkourLab control panel: plain JavaScript modules over the service's REST API (/api/v1),
// served by the service as they are (no build step). Every failing call shows the API's own
// message, at its field where it has one. This module only wires the tabs to what they load;
// each tab's module registers its own handlers when it is loaded. Every tab follows the robot's
// events (events.js: a latched e-stop shows on all of them); index.html loads that module first,
// and it starts itself, so the banner does not wait for Plotly and the other tabs' modules.
import { initTabs } from "./tabs.js";
import { loadJobs } from "./jobs.js";
import { loadExperiments, loadRuns, restoreView } from "./history.js";
import { loadCalibrations } from "./calibration.js";
import "./touchdowns.js";
import { drawLive, refreshRobot, syncLive } from "./robot.js";
import "./connect.js";
import "./simulate.js";
import { showView } from "./view.js";
import { fillChoosers } from "./catalog.js";
import { watchWarming } from "./warming.js";
import { loadWorldTab } from "./worlds.js";
import { loadWorlds } from "./world_list.js";

initTabs((name) => {
  if (name === "history") loadExperiments().then(loadRuns).then(loadCalibrations).catch(() => {});
  if (name === "jobs") loadJobs();
  if (name === "robot") { refreshRobot().catch(() => {}); drawLive(true); }
  syncLive();  // the live websocket is open while the Robot tab is shown
  if (name === "view3d") showView();
  if (name === "world") loadWorldTab().catch(() => {});
});
// The choosers are filled first: a link to a History view may choose a controller.
fillChoosers().catch(() => {}).then(() => restoreView()).catch(() => {});  // a link to a History view (?tab=history&…) opens it
loadWorlds().catch(() => {});  // the worlds fill the Simulate and History choosers
watchWarming();  // "warming up" while the service's workers load after a start
