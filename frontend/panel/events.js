// The robot as every open panel follows it, whatever tab it shows: GET /api/v1/robot/events, the
// service's server-sent events (``event: robot``: the e-stop latch, the link state and the live
// run, at once on connect and within a fraction of a second of each change). Where EventSource is
// missing, or while the stream is down, GET /api/v1/robot every 2 s instead, and the stream is
// tried again. The latched e-stop's banner is shown here and nowhere else.
import { API, $ } from "./api.js";

const POLL_MS = 2000;  // the fallback's GET /robot, while the stream is down
const REOPEN_MS = [2000, 5000, 10000, 30000];  // a stream the browser gave up on (a 503, say) is opened again after these
const listeners = [];
// ``live``: an event came on the stream now open. While it is, the banner follows the stream
// alone: its events come in order, while a call's answer may be older than the last event (a
// GET sent before a press and answered after it would hide the banner for good).
const stream = { source: null, live: false, poll: null, reopen: null, failures: 0 };

// ``listener(summary)`` for each of the stream's events (and each polled status): ``{estop, state, run}``.
export function onRobotEvent(listener) { listeners.push(listener); }

// How the panel follows the robot now: "live" (the stream), "polling" (the fallback), "connecting"
// (the stream's first event has not come yet), or "off" (the page is hidden).
export function robotEventsState() {
  return stream.live ? "live" : stream.poll ? "polling" : stream.source ? "connecting" : "off";
}

// A status the panel got another way (a call's answer, the Robot tab's live websocket): it moves
// the banner only while the stream is not live.
export function statusSeen(status) {
  if (!stream.live) showLatch(status);
}

// A latched e-stop: the banner, with its reason, on every tab until released. An older service
// sends no ``estop``: then the state says it.
function showLatch(status) {
  const estop = status.estop || { latched: status.state === "estopped", reason: null };
  $("#estop-banner").hidden = !estop.latched;
  const by = typeof estop.pressed_by === "string" && estop.pressed_by ? ` Pressed by ${estop.pressed_by}.` : "";
  $("#estop-reason").textContent = estop.latched && estop.reason ? `Reason: ${estop.reason}.${by}` : "";
}

function seen(summary) {
  if (!summary || typeof summary.state !== "string") return;
  showLatch(summary);
  for (const listener of listeners) listener(summary);
}

// Follow the stream while the page is visible. A hidden page lets go of it: a browser keeps six
// connections to a host, and every panel tab left open would hold one; shown again, the stream's
// first event brings the page up to date at once.
export function followRobotEvents() {
  if (document.visibilityState !== "visible") return stopRobotEvents();
  if (typeof EventSource === "undefined") return startPolling();
  if (stream.source || stream.reopen) return;
  const source = new EventSource(`${API}/robot/events`);
  stream.source = source;
  source.addEventListener("robot", (event) => {
    stream.live = true;
    stream.failures = 0;
    stopPolling();
    seen(JSON.parse(event.data));
  });
  source.onerror = () => {
    if (stream.source !== source) return;
    stream.live = false;
    startPolling();
    if (source.readyState !== EventSource.CLOSED) return;  // the browser reconnects by itself (retry: 1 s)
    stream.source = null;  // refused (a 503 past the bound, a service that has none): open it again later
    const delay = REOPEN_MS[Math.min(stream.failures, REOPEN_MS.length - 1)];
    stream.failures += 1;
    stream.reopen = setTimeout(() => { stream.reopen = null; followRobotEvents(); }, delay);
  };
}

export function stopRobotEvents() {
  clearTimeout(stream.reopen);
  stream.reopen = null;
  if (stream.source) stream.source.close();
  stream.source = null;
  stream.live = false;
  stopPolling();
}

// One chain of looks at a time: a look still waiting for its answer when polling stops (or
// stops and starts again) schedules nothing and shows nothing.
function startPolling() {
  if (stream.poll) return;
  const poll = { timer: null };
  stream.poll = poll;
  const look = async () => {
    try {
      const response = await fetch(`${API}/robot`);
      if (response.ok && stream.poll === poll) seen(await response.json());
    } catch (error) {
      // The service did not answer: the banner keeps what it last knew; the next look tries again.
    }
    if (stream.poll === poll) poll.timer = setTimeout(look, POLL_MS);
  };
  look();
}

function stopPolling() {
  if (stream.poll) clearTimeout(stream.poll.timer);
  stream.poll = null;
}

document.addEventListener("visibilitychange", followRobotEvents);
followRobotEvents();  // at once: index.html loads this module first, before Plotly
