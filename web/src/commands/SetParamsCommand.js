import { Command } from './Command.js';

// The parameters a `set_params` message may carry per session kind
// (proto/schemas/ws-client.schema.json#/$defs/set_params: the fields of the scene's model object).
export const PARAM_KEYS = {
  quasi_strip: ['mapping', 'samples', 'method', 'optimizer', 'lambda1', 'lambda2', 'max_iterations'],
  conical_strip: ['np', 'nq', 'h3', 'h4', 'ra', 'objective', 'g1'],
};

const INTEGER = ['samples', 'max_iterations', 'np', 'nq'];
const POSITIVE = ['lambda1', 'lambda2', 'h3', 'h4'];
const ENUMS = {
  method: ['bspline', 'discrete'],
  optimizer: ['lbfgs', 'guided_projection'],
  objective: ['normal_variation', 'bending_energy'],
};

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
  if (key === 'g1') {
    if (typeof value !== 'boolean') throw new TypeError('params.g1: expected true or false');
    return value;
  }
  if (typeof value !== 'number' || !Number.isFinite(value)) throw new TypeError(`params.${key}: expected a number`);
  if (INTEGER.includes(key) && !Number.isInteger(value)) throw new TypeError(`params.${key}: expected an integer`);
  if ((key === 'samples' || key === 'np' || key === 'nq') && value < 2) throw new TypeError(`params.${key}: must be ≥ 2`);
  if (key === 'max_iterations' && value < 1) throw new TypeError('params.max_iterations: must be ≥ 1');
  if (POSITIVE.includes(key) && !(value > 0)) throw new TypeError(`params.${key}: must be > 0`);
  if (key === 'ra' && value < 1) throw new TypeError('params.ra: must be ≥ 1');
  return value;
}

/**
 * quasi_strip / conical_strip sessions: change the model's parameters (a structural, undoable
 * edit; the server rebuilds and solves the strip whole).
 */
export class SetParamsCommand extends Command {
  /**
   * @param {string} kind  'quasi_strip' | 'conical_strip'
   * @param {object} params  any subset of PARAM_KEYS[kind]
   */
  constructor(kind, params, options) {
    super('set_params', options);
    const keys = PARAM_KEYS[kind];
    if (!keys) throw new TypeError(`set_params: applies to quasi_strip and conical_strip sessions, not ${kind}`);
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
