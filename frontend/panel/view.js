// The 3D view tab: the viser view embedded, one of its own per browser, and a status line that
// follows what it shows.
import { API, $ } from "./api.js";

// viser serves the view on its own port of this host; the frame loads it once and keeps it.
// Each browser's view is its own. This page names its view with a random id, carried in the
// view's websocket path (viser's client connects to the address in its `websocket` parameter),
// so History → "3D" opens the replay here and nowhere else.
export const VIEWER = Array.from(crypto.getRandomValues(new Uint8Array(12)), (byte) => byte.toString(16).padStart(2, "0")).join("");

// The status line follows the view while the tab is shown and the page visible: its mode and run
// change inside the view (its own Mode dropdown, Load), by History → "3D", or when it reconnects,
// none of which this page is told of; so GET /view is asked again every FOLLOW_MS (every
// CONNECTING_MS until the view is there), and not at all while the tab is hidden.
const FOLLOW_MS = 2000;
const CONNECTING_MS = 1000;
let timer = null;

const followed = () => !$("#view3d").hidden && document.visibilityState === "visible";

function followLater(ms) {
  clearTimeout(timer);
  timer = followed() ? setTimeout(() => { if (followed()) showView(); }, ms) : null;
}
document.addEventListener("visibilitychange", () => { if (followed()) showView(); });

// GET /view for this page's view, quietly (the line says what went wrong; no banner every 2 s).
async function viewInfo() {
  try {
    const response = await fetch(`${API}/view?viewer=${VIEWER}`);
    const info = await response.json();
    return response.ok ? info : { available: false, reason: `The 3D view's state could not be read: ${info.detail ?? `HTTP ${response.status}`}.`, retry: true };
  } catch {
    return { available: false, reason: "The service did not answer: what the 3D view shows is not known.", retry: true };
  }
}

export async function showView() {
  const info = await viewInfo();
  if (!info.available) {
    $("#view-status").textContent = info.reason;
    // Built in the background at start-up, or the service away for a moment: ask again.
    if (info.starting || info.retry) followLater(info.starting ? CONNECTING_MS : FOLLOW_MS);
    return;
  }
  const page = `${location.protocol}//${location.hostname}:${info.port}/`;
  const socket = `${location.protocol === "https:" ? "wss:" : "ws:"}//${location.hostname}:${info.port}/viewer/${VIEWER}`;
  $("#view-open").href = page; // a window of its own is a view of its own
  const frame = $("#view-frame");
  if (frame.dataset.viewer !== VIEWER) {
    frame.dataset.viewer = VIEWER;
    frame.src = `${page}?websocket=${socket}`;
  }
  const showing = info.mode ? `Mode: ${info.mode}${info.run_id ? `, run ${info.run_id}` : ""}` : "Connecting…";
  $("#view-status").textContent = `${showing} · ${info.updates_per_s} updates/s · this view is yours: what you do in it shows in your browser only.`;
  followLater(info.mode ? FOLLOW_MS : CONNECTING_MS);  // until this page's view has connected, sooner
}
