// Whether the service has warmed up (GET /api/v1/health: "warming" until the workers that answer
// History's pages and simulations have loaded, a few seconds after a start; longer on a fresh
// numba cache). Said once while it warms, looked at again each second, and the note goes when it
// is ready, so a first slow page is explained rather than a mystery.
import { API, $, say } from "./api.js";

const LOOK_EVERY_MS = 1000;
const WARMING = "The service is warming up";
const POOLS = { reads: "History's reads", quick: "simulations", jobs: "the job worker" };

export async function watchWarming() {
  let said = false;
  for (;;) {
    let health;
    try {
      health = await (await fetch(`${API}/health`)).json();
    } catch {
      return;  // no answer: the calls themselves will say so
    }
    if (health.status !== "warming") {
      // Only in place of its own note: a message said since (an error, say) stays.
      if (said && $("#messages").textContent.startsWith(WARMING)) say("The service is ready.");
      return;
    }
    if (!said) {
      const what = (health.warming || []).map((pool) => POOLS[pool] ?? pool).join(", ");
      say(`${WARMING}${what ? ` (${what})` : ""}: the first answers may take a few seconds.`, "info");
      said = true;
    }
    await new Promise((resolve) => setTimeout(resolve, LOOK_EVERY_MS));
  }
}
