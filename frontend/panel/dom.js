// Building the page from API values: every value reaches the page as text, never as markup.
import { $ } from "./api.js";

// An element with ``text`` as its text (never parsed as markup) and ``children`` after it (nodes,
// or strings: text too). No value from the API reaches the page as markup: every row, table and
// status is built from these two.
export function element(tag, text, ...children) {
  const node = document.createElement(tag);
  if (text !== null) node.textContent = text;
  node.append(...children);
  return node;
}

// A table's rows, or one row across every column saying why there are none.
export function fillTable(selector, rows, emptyText) {
  const table = $(selector);
  if (!rows.length) {
    const columns = table.querySelectorAll("thead th").length || 1;
    rows = [element("tr", null, attributes(element("td", emptyText), { colspan: columns, class: "empty" }))];
  }
  table.querySelector("tbody").replaceChildren(...rows);
}

// ``node`` with these attributes, each value set as a string (an attribute value: never markup).
export function attributes(node, values) {
  for (const [name, value] of Object.entries(values)) node.setAttribute(name, String(value));
  return node;
}

export const definitions = (entries) => entries.flatMap(([name, value]) => [element("dt", name), element("dd", String(value))]);
