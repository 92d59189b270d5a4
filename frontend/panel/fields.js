// Form fields checked against the service's own ranges, and errors shown at the field.
//
// The ranges come from one source: the service's OpenAPI document (/openapi.json), the same
// pydantic models that answer 422 — never a second copy written here. An action lists the fields
// it sends and the request-body property each one becomes (readFields); a field that is empty,
// not a number, or out of range is marked (aria-invalid, its message beside it, in the field's
// units) and nothing is sent. A 422 that still comes back is put at its field the same way
// (markApiErrors). The marks clear when the form is next checked.
export const Fields = (() => {
  let schemas = null;
  const ready = fetch("/openapi.json")
    .then((response) => response.json())
    .then((document_) => { schemas = document_.components.schemas; });

  // Follow $ref, and take the non-null branch of an optional field (anyOf [..., {type: null}]).
  function resolve(schema) {
    for (;;) {
      if (schema && schema.$ref) schema = schemas[schema.$ref.split("/").pop()];
      else if (schema && schema.anyOf) schema = schema.anyOf.find((branch) => branch.type !== "null");
      else return schema;
    }
  }

  // The schema of "Model.property.property…", e.g. "LegIn.zeta0" or "MJTFJobCreate.zeta0s".
  function rule(path) {
    const [model, ...properties] = path.split(".");
    let schema = resolve(schemas[model]);
    for (const property of properties) schema = resolve(schema.properties[property]);
    if (schema && schema.type === "array") schema = resolve(schema.items);
    return schema;
  }

  const show = (value) => String(Number(value.toPrecision(6)));

  // Why ``value`` breaks ``schema`` ("" when it does not), in words, with the field's unit.
  function problem(value, schema, unit) {
    const u = unit ? ` ${unit}` : "";
    if (schema.type === "integer" && !Number.isInteger(value)) return "must be a whole number";
    const low = schema.minimum ?? schema.exclusiveMinimum, high = schema.maximum ?? schema.exclusiveMaximum;
    const lowOk = low === undefined || (schema.minimum !== undefined ? value >= low : value > low);
    const highOk = high === undefined || (schema.maximum !== undefined ? value <= high : value < high);
    if (lowOk && highOk) return "";
    const from = low === undefined ? "" : `${schema.minimum !== undefined ? "at least" : "more than"} ${show(low)}`;
    const to = high === undefined ? "" : `${schema.maximum !== undefined ? "at most" : "less than"} ${show(high)}`;
    return `must be ${[from, to].filter(Boolean).join(" and ")}${u}`;
  }

  function clear(form) {
    for (const input of form.querySelectorAll("[aria-invalid=true]")) input.setAttribute("aria-invalid", "false");
    for (const note of form.querySelectorAll(".field-error")) note.remove();
  }

  function mark(input, message) {
    input.setAttribute("aria-invalid", "true");
    const note = document.createElement("span");
    note.className = "field-error";
    note.id = `${input.name}-error`;
    note.textContent = message;  // text, never markup
    input.setAttribute("aria-describedby", note.id);
    input.insertAdjacentElement("afterend", note);
  }

  // The numbers of ``fields`` ([{name, rule, unit, list}]) from ``form``, or null after marking
  // every bad one (the first gets the focus). ``list``: comma-separated numbers.
  async function readFields(form, fields) {
    await ready;
    clear(form);
    const values = {};
    let first = null;
    for (const field of fields) {
      const input = form.elements[field.name];
      const schema = rule(field.rule);
      const texts = field.list ? input.value.split(",") : [input.value];
      const numbers = [];
      let message = "";
      for (const text of texts.map((t) => t.trim())) {
        const value = Number(text);
        if (text === "") message = field.list ? "enter numbers separated by commas" : "enter a number";
        else if (!Number.isFinite(value)) message = `"${text}" is not a number`;
        else message = problem(value, schema, field.unit);
        if (message) break;
        numbers.push(value);
      }
      if (message) {
        mark(input, field.list ? `each ${message}` : message);
        first ??= input;
      } else {
        values[field.name] = field.list ? numbers : numbers[0];
      }
    }
    if (first) {
      first.focus();
      return null;
    }
    return values;
  }

  // A 422's errors put at their fields: ``locations`` maps a body location ("controls.0.zeta0")
  // to an input's name. Returns the messages no field took.
  function markApiErrors(form, detail, locations) {
    const left = [];
    for (const error of Array.isArray(detail) ? detail : []) {
      const location = (error.loc || []).filter((part) => part !== "body").join(".");
      const input = form.elements[locations[location]];
      // pydantic prefixes a validator's own message with its kind ("Value error, …"): not the user's words.
      const message = String(error.msg).replace(/^(Value|Assertion) error, /, "");
      if (input && input.getAttribute("aria-invalid") !== "true") mark(input, message);
      else left.push(location ? `${location}: ${error.msg}` : error.msg);
    }
    return left;
  }

  return { ready, readFields, markApiErrors, clear };
})();
