// The service's REST API as the panel talks to it: the token (the sign-in link, the field and
// whether it is accepted), calls that say what went wrong (a 422 at its fields), the message
// banner, and event handlers whose failures have already been said.
import { Fields } from "./fields.js";

export const API = "/api/v1";
export const $ = (selector, root = document) => root.querySelector(selector);
const TOKEN_KEY = "parkourlab-token";
const tokenInput = $("#token");
const tokenStatus = $("#token-status");

// Sign-in: `parkour serve` prints the panel's address with the token in the fragment
// (#token=…), which browsers never send to the service. Keep it and take it out of the address
// bar (and so out of the history and of what is copied from it). A link opened in a tab that
// already shows the panel changes only the fragment (no page load): hashchange signs that tab in.
function signInFromLink() {
  const fromLink = new URLSearchParams(location.hash.slice(1)).get("token");
  if (!fromLink) return false;
  localStorage.setItem(TOKEN_KEY, fromLink.trim());
  history.replaceState(null, "", location.pathname + location.search);
  tokenInput.value = fromLink.trim();
  return true;
}
signInFromLink();
tokenInput.value = localStorage.getItem(TOKEN_KEY) || "";
addEventListener("hashchange", () => { if (signInFromLink()) checkToken(); });
tokenInput.addEventListener("change", () => {
  localStorage.setItem(TOKEN_KEY, tokenInput.value.trim());
  checkToken();
});

// Whose the token is, as the service says (the person's name; "read": a token that changes nothing).
function signedInAs(who) {
  if (!who || typeof who.name !== "string") return "accepted";
  return who.access === "read" ? `signed in as ${who.name} (reads only)` : `signed in as ${who.name}`;
}

// Whether the service accepts the token in the field, and whose it is, shown beside it.
async function checkToken() {
  const token = tokenInput.value.trim();
  let state = "none", text = "none: you can look, not change";
  if (token) {
    try {
      const response = await fetch(`${API}/auth`, { headers: { Authorization: `Bearer ${token}` } });
      state = response.ok ? "accepted" : "refused";
      text = response.ok ? signedInAs(await response.json()) : "not accepted: open the link parkour serve prints";
    } catch (error) {
      state = "unknown";
      text = "could not be checked: the service did not answer";
    }
  }
  tokenStatus.dataset.state = state;
  tokenStatus.textContent = text;
  tokenInput.setAttribute("aria-invalid", state === "refused" ? "true" : "false");
}
checkToken();

export function say(text, kind = "ok") {
  const box = document.createElement("div");
  box.className = `message ${kind}`;
  box.textContent = text;
  $("#messages").replaceChildren(box);
  if (kind === "ok") setTimeout(() => box.remove(), 4000);
}

function explain(body, status) {
  if (body && Array.isArray(body.detail)) {
    return body.detail.map((e) => {
      const { location, message } = Fields.apiError(e);
      return location ? `${location}: ${message}` : message;
    }).join("; ");
  }
  if (body && body.detail) return body.detail;
  return `HTTP ${status}`;
}

// ``fields``: {form, locations, action} puts a 422's errors at their fields (Fields.markApiErrors);
// what no field on the form takes (a gait not found, a rule across fields, a field the form
// does not have) is said in the API's own words, after ``action`` (the button's name) or the call.
export async function call(method, path, body, fields) {
  // "panel": the job queue keeps each client a share (docs/service.md), so a script cannot crowd it out.
  const headers = { "Content-Type": "application/json", "X-Parkour-Client": "panel" };
  const token = tokenInput.value.trim();
  if (token) headers.Authorization = `Bearer ${token}`;
  let response;
  try {
    response = await fetch(API + path, { method, headers, body: body === undefined ? undefined : JSON.stringify(body) });
  } catch (error) {
    say(`The service did not answer: ${error}`, "error");
    throw error;
  }
  const text = await response.text();
  let data = null;
  try {
    data = text ? JSON.parse(text) : null;
  } catch {  // not the service's JSON (a proxy's page, say): its text is the reason
    if (!response.ok) data = { detail: text.trim().slice(0, 300) || null };
  }
  if (!response.ok && response.status === 422 && fields?.form && data) {
    const { left, marked } = Fields.markApiErrors(fields.form, data.detail, fields.locations);
    const message = left.length ? left.join("; ") : "the service refused the marked field(s)";
    const also = marked ? "; fix the marked field(s) too" : "";
    say(left.length ? `${fields.action ?? `${method} ${path}`}: ${message}${also}` : "Fix the marked field(s): the service refused them.", "error");
    throw Object.assign(new Error(message), { status: 422, detail: data.detail });
  }
  if (!response.ok) {
    const message = response.status === 401
      ? "This needs the API token: open the sign-in link parkour serve prints, or paste data/api_token into the field at the top."
      : explain(data, response.status);
    if (response.status === 401) checkToken();
    say(`${fields?.action ?? `${method} ${path}`}: ${message}`, "error");
    // The status and the API's detail go with it: a caller may show them where they belong (a 422 at a world's segment).
    throw Object.assign(new Error(message), { status: response.status, detail: data?.detail });
  }
  return data;
}

// Handlers: a failed call has already told the user why (say); swallow it here so it is not
// reported again as an uncaught error.
export function on(target, event, handler) {
  (typeof target === "string" ? $(target) : target).addEventListener(event, (e) => {
    Promise.resolve(handler(e)).catch(() => {});
  });
}
