// The 3D view tab: the viser view embedded, one of its own per browser.
import { $, call } from "./api.js";

// viser serves the view on its own port of this host; the frame loads it once and keeps it.
// Each browser's view is its own. This page names its view with a random id, carried in the
// view's websocket path (viser's client connects to the address in its `websocket` parameter),
// so History → "3D" opens the replay here and nowhere else.
export const VIEWER = Array.from(crypto.getRandomValues(new Uint8Array(12)), (byte) => byte.toString(16).padStart(2, "0")).join("");

export async function showView() {
  const info = await call("GET", `/view?viewer=${VIEWER}`);
  if (!info.available) {
    $("#view-status").textContent = info.reason;
    if (info.starting) setTimeout(showView, 1000); // built in the background at start-up
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
  if (!info.mode && !$("#view3d").hidden) setTimeout(showView, 1000);  // until this page's view has connected
  $("#view-status").textContent = `${showing} · ${info.updates_per_s} updates/s · this view is yours: what you do in it shows in your browser only.`;
}
