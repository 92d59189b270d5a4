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
  // The largest whole number a browser holds, and so sends, exactly (2^53 - 1): a whole-number
  // field is held to it even where the API takes more (a seed: up to 2^63 - 1).
  const EXACT = BigInt(Number.MAX_SAFE_INTEGER);
  const EXACT_NOTE = " (the largest whole number a browser sends exactly)";

  // Why whole number ``value`` breaks ``schema`` ("" when it does not): the bounds said as the
  // whole numbers they are, exactly (BigInt: 2^63 - 1 is no double), never rounded.
  function wholeProblem(value, schema, u) {
    let low = schema.minimum ?? schema.exclusiveMinimum, high = schema.maximum ?? schema.exclusiveMaximum;
    if (low !== undefined) low = schema.minimum !== undefined ? BigInt(Math.ceil(low)) : BigInt(Math.floor(low)) + 1n;
    if (high !== undefined) high = schema.maximum !== undefined ? BigInt(Math.floor(high)) : BigInt(Math.ceil(high)) - 1n;
    const capped = high === undefined || high > EXACT;
    if (capped) high = EXACT;
    if (low === undefined || low < -EXACT) low = -EXACT;
    if (BigInt(value) >= low && BigInt(value) <= high) return "";
    return `must be at least ${low} and at most ${high}${u}${capped ? EXACT_NOTE : ""}`;
  }

  // Why ``value`` breaks ``schema`` ("" when it does not), in words, with the field's unit.
  function problem(value, schema, unit) {
    const u = unit ? ` ${unit}` : "";
    if (schema.type === "integer") return Number.isInteger(value) ? wholeProblem(value, schema, u) : "must be a whole number";
    const low = schema.minimum ?? schema.exclusiveMinimum, high = schema.maximum ?? schema.exclusiveMaximum;
    const lowOk = low === undefined || (schema.minimum !== undefined ? value >= low : value > low);
    const highOk = high === undefined || (schema.maximum !== undefined ? value <= high : value < high);
    if (lowOk && highOk) return "";
    const from = low === undefined ? "" : `${schema.minimum !== undefined ? "at least" : "more than"} ${show(low)}`;
    const to = high === undefined ? "" : `${schema.maximum !== undefined ? "at most" : "less than"} ${show(high)}`;
    return `must be ${[from, to].filter(Boolean).join(" and ")}${u}`;
  }

  // The annotation ``key`` the API puts on a property, "Model.property" (e.g. RunCreate's
  // "x-max-rate-times-jumps" on trajectory_rate), or undefined.
  async function annotation(path, key) {
    await ready;
    const [model, property] = path.split(".");
    return resolve(schemas[model])?.properties?.[property]?.[key];
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

  // The numbers of ``fields`` ([{name, rule, unit, list, optional}]) from ``form``, or null after
  // marking every bad one (the first gets the focus). ``list``: comma-separated numbers;
  // ``optional``: left empty, it is left out (the API's default).
  async function readFields(form, fields) {
    await ready;
    clear(form);
    const values = {};
    let first = null;
    for (const field of fields) {
      const input = form.elements[field.name];
      if (field.optional && input.value.trim() === "") continue;
      const schema = rule(field.rule);
      const texts = field.list ? input.value.split(",") : [input.value];
      const numbers = [];
      let message = "";
      for (const text of texts.map((t) => t.trim())) {
        const value = Number(text);
        if (text === "") message = field.list ? "enter numbers separated by commas" : "enter a number";
        else if (!Number.isFinite(value)) message = `"${text}" is not a number`;
        else {
          const broken = problem(value, schema, field.unit);
          message = broken && field.list ? `each ${broken}` : broken;  // a list's range: "each must be …"
        }
        if (message) break;
        numbers.push(value);
      }
      if (message) {
        mark(input, message);
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

  // One error of a 422's detail: where (its loc, less "body", joined by dots) and the message in
  // the user's words — pydantic's "Value error, " prefix dropped, and the location dropped where
  // the service's message starts with it already (a ParameterError's "world.left.points[2]: …"),
  // so that "where: message" says it once.
  function apiError(error) {
    const location = (error.loc || []).filter((part) => part !== "body").join(".");
    let message = String(error.msg).replace(/^(Value|Assertion) error, /, "");
    if (location && message.startsWith(`${location}: `)) message = message.slice(location.length + 2);
    return { location, message };
  }

  // A 422's errors put at their fields: ``locations`` maps a body location ("controls.0.zeta0")
  // to an input's name. Returns {left: the messages no field took, in the API's words; marked:
  // how many fields were marked}. A detail that is one sentence (a gait not found, say) names no
  // field: it is left, whole.
  function markApiErrors(form, detail, locations) {
    if (!Array.isArray(detail)) return { left: detail ? [String(detail)] : [], marked: 0 };
    const left = [];
    let marked = 0;
    for (const error of detail) {
      const { location, message: raw } = apiError(error);
      // A rule across fields (psi0_low_deg must be below psi0_high_deg, the work too big) names its
      // fields in the API's words: said in the form's labels, at the first field it names.
      const named = namedFields(form, raw, locations);
      const message = inLabels(raw, named);
      const at = locations[location] ?? named[0]?.input;
      const input = at === undefined ? null : form.elements[at];
      if (input && !input.matches(":disabled") && input.getAttribute("aria-invalid") !== "true") {
        mark(input, message);
        marked += 1;
      } else {
        left.push(location ? `${location}: ${message}` : message);
      }
    }
    return { left, marked };
  }

  // A request body's schema by its name in the OpenAPI document (the catalog's ``request``), or undefined.
  async function schema(name) {
    await ready;
    return resolve(schemas[name]);
  }

  // A property's own schema, its $ref followed and an optional field's null branch left out.
  const plain = (property) => resolve(property);

  // The form's fields that ``message`` names by their API names ({field, input, label}), in the
  // order they appear; longer names first, so "zeta0_low" is not read as "zeta0".
  function namedFields(form, message, locations) {
    const fields = Object.keys(locations).filter((field) => /^\w+$/.test(field));
    if (!fields.length) return [];
    const found = new Map();
    for (const match of message.matchAll(namePattern(fields))) {
      const input = form.elements[locations[match[0]]];
      if (found.has(match[0]) || !input?.labels?.length) continue;
      const label = input.labels[0].childNodes[0]?.textContent?.trim() || match[0];
      found.set(match[0], { field: match[0], input: locations[match[0]], label: `"${label}"` });
    }
    return [...found.values()];  // in the order the message names them
  }

  // ``message`` with the API names of ``named`` said as the form's labels: a name like psi0_low_deg
  // wherever it stands, a plain word (seeds, jumps) only inside a work formula "(a x b x c)", where
  // it is a field and not prose ("up to 1e9 jumps").
  function inLabels(message, named) {
    if (!named.length) return message;
    const labels = new Map(named.map(({ field, label }) => [field, label]));
    const apiLike = [...labels.keys()].filter((field) => /[_\d]/.test(field));
    const said = (text, fields) => (fields.length ? text.replace(namePattern(fields), (field) => labels.get(field)) : text);
    return said(message, apiLike).replace(/\(([^()]*\bx\b[^()]*)\)/g, (formula) => said(formula, [...labels.keys()]));
  }

  // One pattern for whole API field names, the longest first (so "zeta0_low" is not read as "zeta0").
  const namePattern = (fields) => new RegExp(`\\b(${[...fields].sort((a, b) => b.length - a.length).join("|")})\\b`, "g");

  return { ready, readFields, markApiErrors, apiError, mark, clear, annotation, schema, plain };
})();
