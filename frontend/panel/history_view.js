// What the History tab shows — filters, sort, page, page size, hidden columns, the compare
// basket and the grouping — kept in the address bar's query (?tab=history&kind=robot&page=3…),
// so a link to it opens the same view, and a reload restores it. The token never goes there:
// it rides in the fragment, which api.js takes out at once.

// The run filters as the API names them (GET /api/v1/runs), each a field of #history-form.
export const FILTERS = ["experiment_id", "kind", "status", "end_reason", "loop", "controller", "world_id", "tag", "q"];
export const PAGE_SIZES = [25, 50, 100, 200];
export const COLUMNS = ["kind", "status", "ending", "loop", "controller", "target", "controls", "world", "jumps", "climb",
  "failure", "tags", "notes", "created"];
const DEFAULT = { sort: "-id", page: 1, size: 50 };

// The view the address bar holds: {filters, sort, page, size, hide, basket, by, bins}.
export function readView(search = location.search) {
  const query = new URLSearchParams(search);
  const filters = {};
  for (const name of FILTERS) if (query.get(name)) filters[name] = query.get(name);
  const size = Number(query.get("size"));
  const page = Number(query.get("page"));
  const ids = (query.get("basket") || "").split(",").map(Number).filter((id) => Number.isInteger(id) && id > 0);
  return {
    tab: query.get("tab"),
    filters,
    sort: query.get("sort") || DEFAULT.sort,
    page: Number.isInteger(page) && page >= 1 ? page : DEFAULT.page,
    size: PAGE_SIZES.includes(size) ? size : DEFAULT.size,
    hide: (query.get("hide") || "").split(",").filter((name) => COLUMNS.includes(name)),
    basket: [...new Set(ids)],
    by: query.get("by") || "",
    bins: query.get("bins") || "",
  };
}

// The address of ``view`` (History's query; nothing of the other tabs).
export function viewQuery(view) {
  const query = new URLSearchParams({ tab: "history" });
  for (const name of FILTERS) if (view.filters[name]) query.set(name, view.filters[name]);
  if (view.sort !== DEFAULT.sort) query.set("sort", view.sort);
  if (view.page !== DEFAULT.page) query.set("page", String(view.page));
  if (view.size !== DEFAULT.size) query.set("size", String(view.size));
  if (view.hide.length) query.set("hide", view.hide.join(","));
  if (view.basket.length) query.set("basket", view.basket.join(","));
  if (view.by) query.set("by", view.by);
  if (view.by && view.bins) query.set("bins", view.bins);
  return `?${query}`;
}

// Put ``view`` in the address bar (replacing the entry: paging does not fill the back button).
export function showView(view) {
  const query = viewQuery(view);
  if (query !== location.search) history.replaceState(null, "", location.pathname + query);
  return location.origin + location.pathname + query;
}
