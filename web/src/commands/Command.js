// Base of every server-affecting action (after three.js editor's Command pattern). A command
// knows its message type and fields; `toMessage(op)` builds the exact JSON of
// proto/schemas/ws-client.schema.json. `source` names the UI control that issued it, so a server
// error (matched by op) can be shown next to that control.

export function target(t) {
  if (!t || (t.curve !== 'a' && t.curve !== 'b') || !Number.isInteger(t.index) || t.index < 0) {
    throw new TypeError(`invalid control point target ${JSON.stringify(t)}`);
  }
  return { curve: t.curve, index: t.index };
}

export function point3(p) {
  if (!p || p.length !== 3) throw new TypeError('position: expected 3 numbers');
  const out = [Number(p[0]), Number(p[1]), Number(p[2])];
  if (!out.every(Number.isFinite)) throw new TypeError('position: expected 3 finite numbers');
  return out;
}

export function targetLabel(t) {
  return t ? `${t.curve}[${t.index}]` : '';
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
