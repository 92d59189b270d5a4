// Job forms made from the API: a job kind the page has no form for gets one built from its
// request body's schema in the OpenAPI document (the catalog names it): a number field per
// property that takes a plain number, its default filled in, its description as its title, its
// range checked as every form's is (fields.js). A kind whose body needs more than numbers (legs,
// a list) is left to its own fieldset in index.html, or to the API. So a job kind added to the
// service's registry can be scheduled from the panel with no change here.
import { Fields } from "./fields.js";
import { attributes, element } from "./dom.js";

const SKIPPED = new Set(["kind", "experiment_id", "model"]);  // the kind is the chooser's; the others have their own controls

// The simple number properties of ``request`` (a schema name), or null when a required one is not a number.
async function numberFields(request) {
  const schema = await Fields.schema(request);
  if (!schema?.properties) return null;
  const required = new Set(schema.required || []);
  const fields = [];
  for (const [name, property] of Object.entries(schema.properties)) {
    if (SKIPPED.has(name)) continue;
    const plain = Fields.plain(property);
    if (!plain || !["number", "integer"].includes(plain.type)) {
      if (required.has(name)) return null;
      continue;
    }
    fields.push({ name, plain, required: required.has(name), title: property.description ?? plain.description ?? "" });
  }
  return fields;
}

// A fieldset for ``kind`` ({name, title, request}) built from its schema, or null if it cannot be.
export async function generatedFieldset(kind) {
  const fields = await numberFields(kind.request);
  if (!fields) return null;
  const fieldset = attributes(element("fieldset", null, element("legend", kind.title)), { "data-kind": kind.name, "data-generated": "" });
  for (const field of fields) {
    const input = attributes(element("input", null), { name: `${kind.name}__${field.name}`, type: "number",
      step: field.plain.type === "integer" ? "1" : "any" });
    if (field.plain.default !== undefined && field.plain.default !== null) input.value = String(field.plain.default);
    const label = element("label", `${field.name.replaceAll("_", " ")} `, input);
    if (field.title) label.title = field.title;
    fieldset.append(label);
  }
  fieldset.hidden = true;
  fieldset.disabled = true;
  return { fieldset, fields: fields.map((field) => ({ name: `${kind.name}__${field.name}`, rule: `${kind.request}.${field.name}`, optional: !field.required })) };
}

// The body and the 422's locations of a generated kind's form, from the checked values ``v``.
export function generatedBody(kind, fields, v) {
  const body = { kind }, locations = {};
  for (const field of fields) {
    const property = field.name.slice(kind.length + 2);
    if (v[field.name] !== undefined) body[property] = v[field.name];
    locations[property] = field.name;
    locations[`${kind}.${property}`] = field.name;
  }
  return { body, locations };
}
