// A tiny JSON Schema (2020-12) validator for the subset the devsurf schemas use:
// $ref (local "#/$defs/…" and "other.schema.json#/$defs/…"), type (incl. "integer" and arrays of
// types), const, enum, required, properties, additionalProperties: false, oneOf, items,
// minItems, maxItems, minProperties, minimum, maximum, exclusiveMinimum, exclusiveMaximum, minLength, maxLength;
// "discriminator" selects the oneOf branch by a property's constant.
// Unknown keywords that would change the outcome make it throw, so it cannot pass silently.

const IGNORED = new Set(['$schema', '$id', 'title', 'description', 'default', 'discriminator', 'x-error', '$defs', 'examples', '$comment']);
const KNOWN = new Set(['$ref', 'type', 'const', 'enum', 'required', 'properties', 'additionalProperties', 'oneOf', 'items',
  'minItems', 'maxItems', 'minProperties', 'minimum', 'maximum', 'exclusiveMinimum', 'exclusiveMaximum', 'minLength', 'maxLength']);

function typeOf(v) {
  if (v === null) return 'null';
  if (Array.isArray(v)) return 'array';
  if (Number.isInteger(v)) return 'integer';
  return typeof v;
}

function matchesType(v, t) {
  const actual = typeOf(v);
  if (t === 'number') return actual === 'number' || actual === 'integer';
  return actual === t;
}

function deepEqual(a, b) {
  return JSON.stringify(a) === JSON.stringify(b);
}

/** schemas: {"ws-client.schema.json": {...}, "scene.schema.json": {...}} */
export function makeValidator(schemas) {
  function resolve(ref, base) {
    const [file, pointer] = ref.split('#');
    const docName = file || base;
    const doc = schemas[docName];
    if (!doc) throw new Error(`unknown schema ${docName}`);
    let node = doc;
    for (const part of (pointer || '').split('/').filter(Boolean)) node = node[part];
    if (!node) throw new Error(`unresolved $ref ${ref}`);
    return { node, base: docName };
  }

  function validate(value, schema, base, path, errors) {
    for (const key of Object.keys(schema)) {
      if (!IGNORED.has(key) && !KNOWN.has(key)) throw new Error(`validator: unsupported keyword ${key} at ${path}`);
    }
    if (schema.$ref) {
      const r = resolve(schema.$ref, base);
      validate(value, r.node, r.base, path, errors);
    }
    if (schema.type !== undefined) {
      const types = Array.isArray(schema.type) ? schema.type : [schema.type];
      if (!types.some((t) => matchesType(value, t))) {
        errors.push(`${path}: expected ${types.join('|')}, got ${typeOf(value)}`);
        return;
      }
    }
    if ('const' in schema && !deepEqual(value, schema.const)) errors.push(`${path}: must be ${JSON.stringify(schema.const)}`);
    if (schema.enum && !schema.enum.some((e) => deepEqual(e, value))) errors.push(`${path}: must be one of ${JSON.stringify(schema.enum)}`);
    if (typeof value === 'number') {
      if (schema.minimum !== undefined && value < schema.minimum) errors.push(`${path}: must be ≥ ${schema.minimum}`);
      if (schema.maximum !== undefined && value > schema.maximum) errors.push(`${path}: must be ≤ ${schema.maximum}`);
      if (schema.exclusiveMinimum !== undefined && value <= schema.exclusiveMinimum) errors.push(`${path}: must be > ${schema.exclusiveMinimum}`);
      if (schema.exclusiveMaximum !== undefined && value >= schema.exclusiveMaximum) errors.push(`${path}: must be < ${schema.exclusiveMaximum}`);
    }
    if (typeof value === 'string') {
      if (schema.minLength !== undefined && value.length < schema.minLength) errors.push(`${path}: too short`);
      if (schema.maxLength !== undefined && value.length > schema.maxLength) errors.push(`${path}: too long`);
    }
    if (Array.isArray(value)) {
      if (schema.minItems !== undefined && value.length < schema.minItems) errors.push(`${path}: fewer than ${schema.minItems} items`);
      if (schema.maxItems !== undefined && value.length > schema.maxItems) errors.push(`${path}: more than ${schema.maxItems} items`);
      if (schema.items) value.forEach((v, i) => validate(v, schema.items, base, `${path}[${i}]`, errors));
    }
    if (typeOf(value) === 'object') {
      for (const r of schema.required || []) if (!(r in value)) errors.push(`${path}.${r}: is required`);
      if (schema.minProperties !== undefined && Object.keys(value).length < schema.minProperties) errors.push(`${path}: fewer than ${schema.minProperties} properties`);
      const props = schema.properties || {};
      for (const [k, v] of Object.entries(value)) {
        if (props[k]) validate(v, props[k], base, `${path}.${k}`, errors);
        else if (schema.additionalProperties === false) errors.push(`${path}.${k}: unknown field`);
      }
    }
    if (schema.oneOf && schema.discriminator && typeOf(value) === 'object') {
      // Select the branch by the discriminator property's constant (as the daemon does).
      const prop = schema.discriminator.propertyName;
      const branch = schema.oneOf.find((s) => {
        const r = s.$ref ? resolve(s.$ref, base) : { node: s };
        return r.node.properties && r.node.properties[prop] && deepEqual(r.node.properties[prop].const, value[prop]);
      });
      if (!branch) errors.push(`${path}.${prop}: unknown ${JSON.stringify(value[prop])}`);
      else validate(value, branch, base, path, errors);
    } else if (schema.oneOf) {
      const passing = schema.oneOf.filter((s) => {
        const e = [];
        validate(value, s, base, path, e);
        return e.length === 0;
      });
      if (passing.length !== 1) errors.push(`${path}: matches ${passing.length} of oneOf (expected exactly 1)`);
    }
  }

  return function validateDocument(value, schemaName) {
    const errors = [];
    validate(value, schemas[schemaName], schemaName, '$', errors);
    return errors;
  };
}
