import { Command } from './Command.js';

// The parameters a `set_params` message may carry per session kind
// (proto/schemas/ws-client.schema.json#/$defs/set_params: the fields of the scene's model object).
export const PARAM_KEYS = {
  quasi_strip: ['mapping', 'samples', 'method', 'optimizer', 'lambda1', 'lambda2', 'max_iterations'],
  conical_strip: ['np', 'nq', 'h3', 'h4', 'ra', 'objective', 'g1'],
  quad_mesh: ['weights', 'schedule', 'variable', 'conformal', 'gauss_image', 'glue'],
};

const INTEGER = ['samples', 'max_iterations', 'np', 'nq'];
const POSITIVE = ['lambda1', 'lambda2', 'h3', 'h4'];
const ENUMS = {
  method: ['bspline', 'discrete'],
  optimizer: ['lbfgs', 'guided_projection'],
  objective: ['normal_variation', 'bending_energy'],
  variable: ['mesh', 'unfolding', 'both'],
};

const BOOLEANS = ['g1', 'conformal', 'gauss_image'];

/** quad_mesh `glue`: [{on: 'mesh'|'unfolding', pairs: [[i, j], …]}] (vertex pairs, i ≠ j). */
function checkedGlue(value) {
  if (!Array.isArray(value)) throw new TypeError('params.glue: expected a list of {on, pairs}');
  return value.map((g, k) => {
    if (!g || typeof g !== 'object') throw new TypeError(`params.glue[${k}]: expected {on, pairs}`);
    const on = g.on === undefined ? 'mesh' : g.on;
    if (on !== 'mesh' && on !== 'unfolding') throw new TypeError(`params.glue[${k}].on: expected mesh or unfolding`);
    if (!Array.isArray(g.pairs)) throw new TypeError(`params.glue[${k}].pairs: expected a list of vertex pairs`);
    const pairs = g.pairs.map((p, m) => {
      if (!Array.isArray(p) || p.length !== 2 || !p.every((i) => Number.isInteger(i) && i >= 0)) {
        throw new TypeError(`params.glue[${k}].pairs[${m}]: expected two vertex indices`);
      }
      if (p[0] === p[1]) throw new TypeError(`params.glue[${k}].pairs[${m}]: a vertex is not glued to itself`);
      return [p[0], p[1]];
    });
    return { on, pairs };
  });
}

/** quad_mesh `weights` / `schedule`: an object of finite numbers ≥ 0, merged field by field. */
function checkedNumbers(key, value) {
  if (!value || typeof value !== 'object' || Array.isArray(value)) throw new TypeError(`params.${key}: expected an object of numbers`);
  const out = {};
  for (const [k, v] of Object.entries(value)) {
    if (typeof v !== 'number' || !Number.isFinite(v) || v < 0) throw new TypeError(`params.${key}.${k}: expected a number ≥ 0`);
    out[k] = v;
  }
  if (!Object.keys(out).length) throw new TypeError(`params.${key}: expected at least one field`);
  return out;
}

/** Checks one parameter against the schema's rules; throws a TypeError naming the field. */
function checked(key, value) {
  if (key === 'mapping') {
    if (!value || typeof value !== 'object') throw new TypeError('params.mapping: expected {degree?, coefficients?}');
    const out = {};
    for (const [k, v] of Object.entries(value)) {
      if (k !== 'degree' && k !== 'coefficients') throw new TypeError(`params.mapping.${k}: unknown field`);
      if (!Number.isInteger(v)) throw new TypeError(`params.mapping.${k}: expected an integer`);
      if (k === 'degree' && (v < 1 || v > 9)) throw new TypeError('params.mapping.degree: must be 1 … 9');
      if (k === 'coefficients' && (v < 2 || v > 10000)) throw new TypeError('params.mapping.coefficients: must be 2 … 10000');
      out[k] = v;
    }
    if (!Object.keys(out).length) throw new TypeError('params.mapping: expected degree or coefficients');
    return out;
  }
  if (ENUMS[key]) {
    if (!ENUMS[key].includes(value)) throw new TypeError(`params.${key}: expected one of ${ENUMS[key].join(', ')}`);
    return value;
  }
  if (BOOLEANS.includes(key)) {
    if (typeof value !== 'boolean') throw new TypeError(`params.${key}: expected true or false`);
    return value;
  }
  if (key === 'glue') return checkedGlue(value);
  if (key === 'weights' || key === 'schedule') return checkedNumbers(key, value);
  if (typeof value !== 'number' || !Number.isFinite(value)) throw new TypeError(`params.${key}: expected a number`);
  if (INTEGER.includes(key) && !Number.isInteger(value)) throw new TypeError(`params.${key}: expected an integer`);
  if ((key === 'samples' || key === 'np' || key === 'nq') && value < 2) throw new TypeError(`params.${key}: must be ≥ 2`);
  if (key === 'max_iterations' && value < 1) throw new TypeError('params.max_iterations: must be ≥ 1');
  if (POSITIVE.includes(key) && !(value > 0)) throw new TypeError(`params.${key}: must be > 0`);
  if (key === 'ra' && value < 1) throw new TypeError('params.ra: must be ≥ 1');
  return value;
}

/**
 * quasi_strip / conical_strip / quad_mesh sessions: change the model's parameters (a structural,
 * undoable edit; the server rebuilds the model — strips are solved whole; a quad_mesh's `glue`
 * replaces the list, its weights and schedule are merged field by field).
 */
export class SetParamsCommand extends Command {
  /**
   * @param {string} kind  'quasi_strip' | 'conical_strip' | 'quad_mesh'
   * @param {object} params  any subset of PARAM_KEYS[kind]
   */
  constructor(kind, params, options) {
    super('set_params', options);
    const keys = PARAM_KEYS[kind];
    if (!keys) throw new TypeError(`set_params: applies to quasi_strip, conical_strip and quad_mesh sessions, not ${kind}`);
    this.params = {};
    for (const [k, v] of Object.entries(params || {})) {
      if (v === undefined) continue;
      if (!keys.includes(k)) throw new TypeError(`params.${k}: not a ${kind} parameter`);
      this.params[k] = checked(k, v);
    }
    if (!Object.keys(this.params).length) throw new TypeError('params: expected at least one parameter');
    this.name = `set ${Object.keys(this.params).join(', ')}`;
  }

  fields() {
    return { params: JSON.parse(JSON.stringify(this.params)) };
  }
}
