// Checks a JSON document against a JSON Schema (draft 2020-12), for the
// subset our schemas use: type, enum, const, required, properties,
// additionalProperties, items, minimum, maximum, minLength, pattern, and
// local $ref ("#/$defs/name"). A keyword outside the subset is an error, so
// a schema cannot silently outgrow its checker.
//
//   node tests/tools/check_schema.mjs SCHEMA.json DOC.json
//       exit 0 when DOC is valid, 1 with the violations otherwise.
//   node tests/tools/check_schema.mjs SCHEMA.json DOC.json --self-test
//       DOC must be valid, and removing any one required top-level field
//       (or putting a string where the schema wants a number) must make it
//       invalid: proves the check can fail.
import fs from 'node:fs';

const KNOWN = new Set(['$schema', '$id', 'title', 'description', '$defs', 'type', 'enum', 'const',
  'required', 'properties', 'additionalProperties', 'items', 'minimum', 'maximum', 'minLength',
  'pattern', '$ref']);

function typeOf(v) {
  if (v === null) return 'null';
  if (Array.isArray(v)) return 'array';
  if (typeof v === 'number') return Number.isInteger(v) ? 'integer' : 'number';
  return typeof v;  // string, boolean, object
}

function typeMatches(want, v) {
  const got = typeOf(v);
  return want === got || (want === 'number' && got === 'integer');
}

export function validate(root, schema, value, at = '$', errors = []) {
  for (const key of Object.keys(schema))
    if (!KNOWN.has(key)) throw new Error(`schema keyword '${key}' at ${at} is not supported by check_schema.mjs`);
  if (schema.$ref) {
    const m = /^#\/\$defs\/(.+)$/.exec(schema.$ref);
    if (!m || !root.$defs?.[m[1]]) throw new Error(`unresolvable $ref ${schema.$ref}`);
    validate(root, root.$defs[m[1]], value, at, errors);
  }
  if (schema.type) {
    const types = Array.isArray(schema.type) ? schema.type : [schema.type];
    if (!types.some((t) => typeMatches(t, value))) {
      errors.push(`${at}: expected ${types.join('|')}, got ${typeOf(value)}`);
      return errors;
    }
  }
  if (schema.enum && !schema.enum.some((e) => JSON.stringify(e) === JSON.stringify(value)))
    errors.push(`${at}: ${JSON.stringify(value)} not one of ${JSON.stringify(schema.enum)}`);
  if ('const' in schema && JSON.stringify(schema.const) !== JSON.stringify(value))
    errors.push(`${at}: must be ${JSON.stringify(schema.const)}`);
  if (typeof value === 'number') {
    if (schema.minimum !== undefined && value < schema.minimum) errors.push(`${at}: ${value} < ${schema.minimum}`);
    if (schema.maximum !== undefined && value > schema.maximum) errors.push(`${at}: ${value} > ${schema.maximum}`);
  }
  if (typeof value === 'string') {
    if (schema.minLength !== undefined && value.length < schema.minLength) errors.push(`${at}: shorter than ${schema.minLength}`);
    if (schema.pattern && !new RegExp(schema.pattern, 'u').test(value)) errors.push(`${at}: does not match ${schema.pattern}`);
  }
  if (typeOf(value) === 'object') {
    for (const r of schema.required ?? [])
      if (!(r in value)) errors.push(`${at}: missing required '${r}'`);
    for (const [k, v] of Object.entries(value)) {
      if (schema.properties && k in schema.properties) validate(root, schema.properties[k], v, `${at}.${k}`, errors);
      else if (schema.additionalProperties === false) errors.push(`${at}: unexpected '${k}'`);
      else if (typeof schema.additionalProperties === 'object')
        validate(root, schema.additionalProperties, v, `${at}.${k}`, errors);
    }
  }
  if (Array.isArray(value) && schema.items)
    value.forEach((v, i) => validate(root, schema.items, v, `${at}[${i}]`, errors));
  return errors;
}

const [schemaPath, docPath, mode] = process.argv.slice(2);
if (!schemaPath || !docPath) {
  console.error('usage: node check_schema.mjs SCHEMA.json DOC.json [--self-test]');
  process.exit(2);
}
const schema = JSON.parse(fs.readFileSync(schemaPath, 'utf8'));
const doc = JSON.parse(fs.readFileSync(docPath, 'utf8'));
const errors = validate(schema, schema, doc);
if (errors.length) {
  console.log(`${docPath}: invalid\n  ${errors.join('\n  ')}`);
  process.exit(1);
}
if (mode === '--self-test') {
  let failures = 0;
  for (const field of schema.required ?? []) {
    const broken = structuredClone(doc);
    delete broken[field];
    if (validate(schema, schema, broken).length === 0) {
      console.log(`self-test: removing '${field}' was not detected`);
      failures++;
    }
  }
  const wrongType = structuredClone(doc);
  wrongType.uv.coverage = 'all';
  if (validate(schema, schema, wrongType).length === 0) {
    console.log('self-test: a string uv.coverage was not detected');
    failures++;
  }
  if (failures) process.exit(1);
  console.log(`${docPath}: valid; ${(schema.required ?? []).length} required-field removals and a type error detected`);
  process.exit(0);
}
console.log(`${docPath}: valid`);
