// Validate documents against JSON Schemas with ajv (draft 2020-12, ajv's default strict
// mode: unknown keywords and formats refused; regexes compiled as ECMA-262 with the "u"
// flag, as editors' JSON language services do). ajv's warnings (its "log" strictness) are
// returned beside the schema's name, so the test can show them.
// stdin: {"schemas": {name: schema}, "cases": [{"id": str, "schema": name, "data": any}]}
// stdout: {"schemas": {name: null | "why the schema is refused"}, "warnings": {name: [..]},
//          "cases": {id: null | ["first errors"]}}
import Ajv2020 from "ajv/dist/2020.js";
import addFormats from "ajv-formats";

const chunks = [];
for await (const chunk of process.stdin) chunks.push(chunk);
const input = JSON.parse(Buffer.concat(chunks).toString("utf8"));

const out = { schemas: {}, warnings: {}, cases: {} };
const validators = {};
for (const [name, schema] of Object.entries(input.schemas)) {
  const warnings = [];
  const logger = { log() {}, warn: (...a) => warnings.push(a.join(" ")), error: (...a) => warnings.push(a.join(" ")) };
  const ajv = new Ajv2020({ allErrors: true, allowUnionTypes: true, logger });
  out.warnings[name] = warnings;
  addFormats(ajv);
  try {
    validators[name] = ajv.compile(schema);
    out.schemas[name] = null;
  } catch (err) {
    out.schemas[name] = String(err && err.message ? err.message : err);
  }
}
for (const c of input.cases) {
  const validate = validators[c.schema];
  if (!validate) { out.cases[c.id] = ["schema " + c.schema + " did not compile"]; continue; }
  out.cases[c.id] = validate(c.data) ? null
    : validate.errors.slice(0, 5).map(e => `${e.instancePath || "/"} ${e.message}`);
}
process.stdout.write(JSON.stringify(out));
