// Shared by the unit tests: the proto/ schemas as validators, and encoders of the daemon's typed
// arrays (what a geometry message carries).
import { readFileSync } from 'node:fs';
import { fileURLToPath } from 'node:url';
import { encodeArray } from '../../src/geometry/decode.js';
import { makeValidator } from './jsonschema.js';

const schemaDir = fileURLToPath(new URL('../../../proto/schemas/', import.meta.url));
const load = (name) => JSON.parse(readFileSync(schemaDir + name, 'utf8'));

/** Validator of the client messages and scenes (`validate(value, 'ws-client.schema.json')`). */
export const validate = makeValidator({ 'ws-client.schema.json': load('ws-client.schema.json'), 'scene.schema.json': load('scene.schema.json') });

/** Whether a client message (a command's JSON) matches proto/schemas/ws-client.schema.json. */
export const validClient = (msg) => validate(JSON.parse(JSON.stringify(msg)), 'ws-client.schema.json');

/** A float32 / int32 array of rows as the daemon encodes it. */
export const f32 = (rows, shape) => encodeArray(Float32Array.from(rows.flat()), shape);
export const i32 = (rows, shape) => encodeArray(Int32Array.from(rows.flat()), shape);
