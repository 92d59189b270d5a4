// The tabs: the WAI-ARIA tabs pattern (each tab controls its panel, only the selected one is in
// the Tab order, the arrow keys, Home and End move between tabs), and what showing one loads.
import { $, on } from "./api.js";

// ``shown(name)`` runs each time a tab is shown (main.js: what each tab loads).
export function initTabs(shown) {
  const tabs = [...document.querySelectorAll("nav [role=tab]")];
  for (const tab of tabs) {
    tab.id = `tab-${tab.dataset.tab}`;
    tab.setAttribute("aria-controls", tab.dataset.tab);
    tab.tabIndex = tab.getAttribute("aria-selected") === "true" ? 0 : -1;
    $(`#${tab.dataset.tab}`).setAttribute("aria-labelledby", tab.id);
  }
  on("nav[role=tablist]", "keydown", (event) => {
    const at = tabs.indexOf(document.activeElement);
    if (at < 0) return;
    const to = { ArrowRight: at + 1, ArrowLeft: at - 1, Home: 0, End: tabs.length - 1 }[event.key];
    if (to === undefined) return;
    event.preventDefault();
    const next = tabs[(to + tabs.length) % tabs.length];
    next.focus();
    next.click();
  });
  for (const tab of tabs) {
    on(tab, "click", () => {
      for (const other of tabs) {
        other.setAttribute("aria-selected", String(other === tab));
        other.tabIndex = other === tab ? 0 : -1;
      }
      for (const panel of document.querySelectorAll("main [role=tabpanel]")) panel.hidden = panel.id !== tab.dataset.tab;
      shown(tab.dataset.tab);
    });
  }
}

export function selectTab(name) { $(`nav [data-tab=${name}]`).click(); }
