// Base of every server-affecting action (after three.js editor's Command pattern). A command
// knows its message type and fields; `toMessage(op)` builds the exact JSON of
// proto/schemas/ws-client.schema.json. `source` names the UI control that issued it, so a server
// error (matched by op) can be shown next to that control.

const isIndex = (v) => Number.isInteger(v) && v >= 0;

/** Curve names of control-point targets: strip a|b, quasi_strip c1|c2, conical_strip p|q. */
export const CURVE_NAMES = ['a', 'b', 'c1', 'c2', 'p', 'q'];

/**
 * A point as the protocol addresses it: a control point {curve, index} of a strip ('a'|'b'),
 * quasi_strip ('c1'|'c2') or conical_strip ('p'|'q'), or in a
 * composite a vertex {vertex} or control point `index` of an S edge {edge, index}; in a quad_mesh
 * a vertex of M {vertex} or of its unfolding M′ {vertex, on: 'unfolding'} ({on: 'mesh'} is M), or
 * a control point of its control net {vertex, on: 'control'} (spline surfaces).
 */
export function target(t) {
  if (t && CURVE_NAMES.includes(t.curve) && isIndex(t.index) && t.vertex === undefined && t.edge === undefined) {
    return { curve: t.curve, index: t.index };
  }
  if (t && isIndex(t.vertex) && t.curve === undefined && t.edge === undefined) {
    if (t.on === undefined || t.on === 'mesh') return { vertex: t.vertex };
    if (t.on === 'unfolding' || t.on === 'control') return { vertex: t.vertex, on: t.on };
  }
  if (t && isIndex(t.edge) && isIndex(t.index) && t.curve === undefined && t.vertex === undefined) {
    return { edge: t.edge, index: t.index };
  }
  throw new TypeError(`invalid point target ${JSON.stringify(t)}`);
}

/**
 * The target of a constraint entry: state messages nest it ({target, position, …}), scene lists
 * keep the addressing keys flat ({curve, index, position, …}).
 */
export function targetOf(entry) {
  if (!entry) return null;
  const t = entry.target || entry;
  if (t.curve !== undefined) return { curve: t.curve, index: t.index };
  if (t.vertex !== undefined) return t.on === 'unfolding' || t.on === 'control' ? { vertex: t.vertex, on: t.on } : { vertex: t.vertex };
  if (t.edge !== undefined) return { edge: t.edge, index: t.index };
  return null;
}

/** A string key of a target ('a3', 'v3', 'u3' (a vertex of M′), 'm3' (a control point of M), 'e0:2'), '' for none. */
export function targetKey(t) {
  const x = targetOf(t);
  if (!x) return '';
  if (x.curve !== undefined) return `${x.curve}${x.index}`;
  if (x.vertex !== undefined) return `${x.on === 'unfolding' ? 'u' : x.on === 'control' ? 'm' : 'v'}${x.vertex}`;
  return `e${x.edge}:${x.index}`;
}

/** Whether two targets (or constraint entries) address the same point. */
export function sameTarget(a, b) {
  const ka = targetKey(a);
  return ka !== '' && ka === targetKey(b);
}

export function point3(p) {
  if (!p || p.length !== 3) throw new TypeError('position: expected 3 numbers');
  const out = [Number(p[0]), Number(p[1]), Number(p[2])];
  if (!out.every(Number.isFinite)) throw new TypeError('position: expected 3 finite numbers');
  return out;
}

export function targetLabel(t) {
  const x = targetOf(t);
  if (!x) return '';
  if (x.curve !== undefined) return `${x.curve}[${x.index}]`;
  if (x.on === 'control') return `control point ${x.vertex}`;
  if (x.vertex !== undefined) return `vertex ${x.vertex}${x.on === 'unfolding' ? ' of M′' : ''}`;
  return `edge ${x.edge} [${x.index}]`;
}

export class Command {
  /**
   * @param {string} type  the message type
   * @param {object} [options]  {source}: the UI control that issued the command
   */
  constructor(type, options = {}) {
    this.type = type;
    this.source = options.source || null;
    this.name = type;
  }

  /** The message fields besides type and op (no undefined members). */
  fields() {
    return {};
  }

  /** The JSON message with operation id `op` (omitted when op is null/undefined). */
  toMessage(op) {
    const msg = { type: this.type };
    if (op !== undefined && op !== null) msg.op = op;
    for (const [k, v] of Object.entries(this.fields())) if (v !== undefined) msg[k] = v;
    return msg;
  }
}
