// The object fields of a job form built from its request's schema (job_forms.js): a property that
// is an object of its own (a $ref to a component schema; an optional one inside anyOf with null)
// — a reach's or a plan's starting state {xdot, ydot}, the noise, a plan's importance_sampling —
// made a fieldset of its properties, one level deep: a number or a whole number (a list of them,
// comma-separated), a yes/no (a checkbox), one of a few names (a select) or several of them (a
// multi-select: Ctrl- or Shift-click, as the controllers' chooser). Each input has its property's
// description and range as its title and the schema's default as its value; the numbers are
// checked against the API's ranges as every field's are (fields.js), a list of names against its
// count. An optional object (one the request does not require: the service has a default for it)
// has a checkbox "set <name>" in its legend that enables its fieldset: unchecked, the field is
// left out of the body and the service's default applies. A 422 at a property
// (["body", kind, field, property, (item)]) is put at its input.
import { Fields } from "./fields.js";
import { attributes, element } from "./dom.js";

// A property's name in a label's words: "goal_height_m" -> "goal height [m]".
export const words = (name) => name.replace(/_(m|deg|s)$/, " [$1]").replaceAll("_", " ");

const MAX_ITEMS = 64;  // the most items of a list whose 422 (at an item) is put at its input

// What kind of input ``property`` takes (number, list, boolean, choice, choices), or null: none here.
function inputKind(property) {
  const plain = Fields.plain(property);
  if (!plain) return null;
  if (Array.isArray(plain.enum)) return "choice";
  if (plain.type === "boolean") return "boolean";
  if (plain.type === "number" || plain.type === "integer") return "number";
  if (plain.type !== "array") return null;
  const items = Fields.plain(plain.items);
  if (Array.isArray(items?.enum)) return "choices";
  return items?.type === "number" || items?.type === "integer" ? "list" : null;
}

// A number's range in words: "in [1, 5]", "in [-100, 0)", "at least 0"; "" when it has none.
function rangeWords(schema) {
  const show = (value) => (schema.type === "integer" ? String(value) : String(Number(value.toPrecision(6))));
  const low = schema.minimum ?? schema.exclusiveMinimum, high = schema.maximum ?? schema.exclusiveMaximum;
  const closedLow = schema.minimum !== undefined, closedHigh = schema.maximum !== undefined;
  if (low !== undefined && high !== undefined) return `in ${closedLow ? "[" : "("}${show(low)}, ${show(high)}${closedHigh ? "]" : ")"}`;
  if (low !== undefined) return `${closedLow ? "at least" : "more than"} ${show(low)}`;
  if (high !== undefined) return `${closedHigh ? "at most" : "less than"} ${show(high)}`;
  return "";
}

// An input's title: the property's description, then its range or its choices.
function titleOf(kind, property, plain) {
  const items = kind === "list" || kind === "choices" ? Fields.plain(plain.items) : null;
  const said = {
    number: rangeWords(plain),
    list: items && rangeWords(items) ? `comma-separated, each ${rangeWords(items)}` : "comma-separated",
    choice: `one of ${plain.enum?.join(", ")}`,
    choices: `${plain.minItems ? `at least ${plain.minItems} of` : "any of"} ${items?.enum?.join(", ")} (Ctrl- or Shift-click for several)`,
    boolean: "",
  }[kind];
  return [property.description ?? plain.description, said].filter(Boolean).join("; ");
}

// The input of one property, named ``name``, showing ``initial`` (the schema's default).
function inputFor(kind, name, plain, initial, required) {
  if (kind === "boolean") {
    const box = attributes(element("input", null), { name, type: "checkbox" });
    box.checked = initial === true;
    return box;
  }
  if (kind === "choice" || kind === "choices") {
    const names = kind === "choice" ? plain.enum : Fields.plain(plain.items).enum;
    const chosen = new Set(kind === "choice" ? [initial] : initial ?? []);
    const options = names.map((value) => new Option(String(value), String(value), false, chosen.has(value)));
    if (kind === "choice" && !required && (initial === undefined || initial === null)) options.unshift(new Option("the default", "", true, true));
    const select = attributes(element("select", null), kind === "choices" ? { name, multiple: "", size: Math.min(names.length, 5) } : { name });
    select.append(...options);  // after "multiple": a single choice would keep one selected option only
    return select;
  }
  const input = attributes(element("input", null), kind === "list" ? { name, size: 12 }
    : { name, type: "number", step: plain.type === "integer" ? "1" : "any" });
  if (initial !== undefined && initial !== null) input.value = Array.isArray(initial) ? initial.join(", ") : String(initial);
  return input;
}

// The object field ``name`` (its ``property`` schema) of ``kind``'s request (``request``: its
// schema's name), or null when one of its required properties takes no input here (a required
// object then leaves the kind to the API). ``required``: the request requires it (no checkbox).
export function objectField(kind, request, name, property, required) {
  const schema = Fields.plain(property);
  if (schema?.type !== "object" || !schema.properties) return null;
  const own = new Set(schema.required || []);
  const given = property.default && typeof property.default === "object" ? property.default : {};  // noise: its default object
  const at = (part) => `${kind}__${name}__${part}`;
  const parts = [];
  for (const [part, inner] of Object.entries(schema.properties)) {
    const kindOf = inputKind(inner);
    if (!kindOf) {
      if (own.has(part)) return null;
      continue;  // left out: the service's default
    }
    const plain = Fields.plain(inner);
    parts.push({ part, kind: kindOf, plain, required: own.has(part), initial: given[part] ?? inner.default ?? plain.default, title: titleOf(kindOf, inner, plain) });
  }
  if (!parts.length) return null;

  const labels = parts.map((p) => {
    const input = inputFor(p.kind, at(p.part), p.plain, p.initial, p.required);
    const label = p.kind === "boolean" ? attributes(element("label", null, input, ` ${words(p.part)}`), { class: "inline" })
      : element("label", `${words(p.part)} `, input);
    if (p.title) label.title = p.title;
    return label;
  });
  const about = (property.description ?? schema.description ?? "").replaceAll("``", "");
  const toggle = required ? null : attributes(element("input", null), { name: `${kind}__${name}`, type: "checkbox" });
  const legend = element("legend", null, toggle ? attributes(element("label", null, toggle, ` set ${words(name)}`), { class: "inline" }) : words(name));
  const fieldset = attributes(element("fieldset", null, legend, ...labels), { class: "object-field", "data-object": name });
  if (about) legend.title = about;
  if (toggle) {
    fieldset.disabled = true;  // the legend's checkbox stays enabled (HTML: a fieldset's first legend is not disabled with it)
    toggle.addEventListener("change", () => { fieldset.disabled = !toggle.checked; });
  }
  const isSet = (form) => required || form.elements[`${kind}__${name}`].checked;

  // A 422's locations: the object itself at its checkbox (or its first input), each property at its input.
  const locations = { [name]: toggle ? `${kind}__${name}` : at(parts[0].part) };
  for (const p of parts) {
    locations[`${name}.${p.part}`] = at(p.part);
    if (p.kind === "list" || p.kind === "choices") {
      for (let i = 0; i < Math.min(p.plain.maxItems ?? MAX_ITEMS, MAX_ITEMS); i += 1) locations[`${name}.${p.part}.${i}`] = at(p.part);
    }
  }

  return {
    name,
    node: fieldset,
    locations,
    // The number fields to check now (none while it is not set): readFields' fields.
    fields: (form) => (isSet(form) ? parts.filter((p) => p.kind === "number" || p.kind === "list")
      .map((p) => ({ name: at(p.part), rule: `${request}.${name}.${p.part}`, optional: !p.required, list: p.kind === "list" })) : []),
    // Whether its lists of names hold as many as the API takes (else they are marked); after readFields.
    valid(form) {
      if (!isSet(form)) return true;
      let ok = true;
      for (const p of parts.filter((q) => q.kind === "choices")) {
        const select = form.elements[at(p.part)], count = select.selectedOptions.length;
        const low = p.plain.minItems ?? 0, high = p.plain.maxItems ?? Infinity;
        if (count < low || count > high) {
          Fields.mark(select, count < low ? `choose at least ${low}` : `choose at most ${high}`);
          ok = false;
        }
      }
      return ok;
    },
    // The object the body sends, from the checked values ``v``; undefined when it is not set.
    value(form, v) {
      if (!isSet(form)) return undefined;
      const object = {};
      for (const p of parts) {
        const input = form.elements[at(p.part)];
        if (p.kind === "boolean") object[p.part] = input.checked;
        else if (p.kind === "choices") object[p.part] = [...input.selectedOptions].map((option) => option.value);
        else if (p.kind === "choice") {
          if (input.value !== "") object[p.part] = p.plain.enum.find((value) => String(value) === input.value);
        } else if (v[at(p.part)] !== undefined) object[p.part] = v[at(p.part)];
      }
      return object;
    },
  };
}
