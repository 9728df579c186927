// Parameters of the strips between two given curves (lil-gui, like the solver panel): quasi_strip
// (Bo et al.: the mapping σ, samples, optimizer) and conical_strip (Chu et al.: samples, H3, H4, ra,
// objective, G1). Each change is a SetParamsCommand; the server rebuilds and solves the strip
// whole. The control shows "pending" until the ack; an error reverts it to the server's value and
// shows under it.

import GUI from 'lil-gui';
import { SetParamsCommand } from '../commands/SetParamsCommand.js';
import { PendingControls } from './PendingControls.js';
import { typedNumberProblem } from './SolverPanel.js';

// [key, label, options]; options: {min, max, step} for numbers, {choices} for selects, {bool}.
// Keys "mapping.degree" / "mapping.coefficients" go into the params' mapping object.
export const PARAM_FIELDS = {
  quasi_strip: [
    ['mapping.degree', 'σ degree', { min: 1, max: 9, step: 1 }],
    ['mapping.coefficients', 'σ coefficients', { min: 2, max: 200, step: 1 }],
    ['samples', 'sample rulings', { min: 2, max: 1000, step: 1 }],
    ['method', 'mapping', { choices: ['bspline', 'discrete'] }],
    ['optimizer', 'optimizer', { choices: ['lbfgs', 'guided_projection'] }],
    ['lambda1', 'λ1 developability', { min: 0.001, step: 1 }],
    ['lambda2', 'λ2 unit normals', { min: 0.001, step: 0.1 }],
  ],
  conical_strip: [
    ['np', 'samples on P', { min: 2, max: 400, step: 1 }],
    ['nq', 'samples on Q', { min: 2, max: 400, step: 1 }],
    ['h3', 'H3 (triangles)', { min: 0.001, step: 0.05 }],
    ['h4', 'H4 (quads)', { min: 0.001, step: 0.05 }],
    ['ra', 'ra (length ratio)', { min: 1, max: 5, step: 0.05 }],
    ['objective', 'objective', { choices: ['normal_variation', 'bending_energy'] }],
    ['g1', 'G1 adjustment', { bool: true }],
  ],
};

const INTEGER_KEYS = ['mapping.degree', 'mapping.coefficients', 'samples', 'np', 'nq'];

/** The params object of a set_params message for one changed field. */
export function paramsFor(key, value) {
  const v = INTEGER_KEYS.includes(key) ? Math.round(value) : value;
  if (key.startsWith('mapping.')) return { mapping: { [key.slice('mapping.'.length)]: v } };
  return { [key]: v };
}

/** The scene model's value of a field key. */
export function modelValue(model, key) {
  if (!model) return undefined;
  if (key.startsWith('mapping.')) return model.mapping ? model.mapping[key.slice('mapping.'.length)] : undefined;
  return model[key];
}

export class ParamsPanel {
  constructor(parent, { state, send, errorSlots }) {
    this.state = state;
    this.send = send;
    this.errorSlots = errorSlots;
    this.parent = parent;
    this.kind = null;
    this.gui = null;
    this.values = {};
    this.controllers = new Map();
    this.refused = new Map();  // key → why the text last typed into its field was not taken
    this.pending = new PendingControls('set_params', 'params:', (key) => this.controllers.get(key));
    state.on('scene', () => this.refresh());
    state.on('session', () => this.refresh());
    state.on('editable', () => this.refresh());
    state.on('ack', ({ command }) => this._settled(command, null));
    state.on('error', ({ command, message }) => this._settled(command, message));
    this.refresh();
  }

  _build(kind) {
    if (this.gui) this.gui.destroy();
    this.gui = null;
    this.controllers.clear();
    this.pending.clear();
    this.kind = kind;
    const fields = PARAM_FIELDS[kind];
    this.parent.hidden = !fields;
    if (!fields) return;
    this.gui = new GUI({ container: this.parent, title: kind === 'quasi_strip' ? 'Strip parameters (Bo et al.)' : 'Patch parameters (Chu et al.)' });
    this.gui.domElement.classList.add('solver-gui', 'params-gui');
    this.gui.domElement.dataset.testid = 'params-panel';
    for (const [key, label, o] of fields) {
      this.values[key] = o.bool ? false : o.choices ? o.choices[0] : o.min;
      let c;
      if (o.choices) c = this.gui.add(this.values, key, o.choices);
      else if (o.bool) c = this.gui.add(this.values, key);
      else if (o.max !== undefined) c = this.gui.add(this.values, key, o.min, o.max, o.step);
      else c = this.gui.add(this.values, key).min(o.min).step(o.step);
      c.name(label);
      c.domElement.dataset.param = key;
      c.onFinishChange((value) => this._changed(key, value));
      // lil-gui clamps typed text to the range without a word (1 sample became 2): say why a typed
      // value is not taken, as the Solver panel does (its 'change' comes before lil-gui's finish).
      if (c.$input && o.min !== undefined && !o.choices && !o.bool) {
        c.$input.addEventListener('change', () =>
          this._checkTyped(key, label, { ...o, integer: INTEGER_KEYS.includes(key) }, c.$input.value));
      }
      c.domElement.after(this.errorSlots.slot(`params:${key}`));
      this.controllers.set(key, c);
    }
  }

  _checkTyped(key, label, { min, max, integer }, text) {
    const why = typedNumberProblem(text, { min, max, integer });
    if (why) {
      this.refused.set(key, why);
      this.errorSlots.show(`params:${key}`, `${label}: ${why}`);
      this.refresh(true);  // back to the server's value
      return;
    }
    this.refused.delete(key);
    this.errorSlots.clear(`params:${key}`);
  }

  _changed(key, value) {
    if (this.refused.has(key)) {
      // lil-gui's own finish of the refused text (clamped): not sent. The refusal is spent, so the
      // slider moved next is taken.
      this.refused.delete(key);
      this.refresh(true);
      return;
    }
    let command;
    try {
      command = new SetParamsCommand(this.kind, paramsFor(key, value), { source: `params:${key}` });
    } catch (e) {
      this.errorSlots.show(`params:${key}`, e.message);
      this.refresh(true);
      return;
    }
    const op = this.send(command);
    if (op === null || op === undefined) {
      this.refresh(true);
      return;
    }
    this.pending.sent(key);
  }

  _settled(command, error) {
    if (this.pending.settled(command) === null) return;
    if (error) this.refresh(true);
  }

  /** Shows the scene's values (controls with a change in flight keep the user's value). */
  refresh(force = false) {
    const model = this.state.scene && this.state.scene.model;
    const kind = model ? model.kind : null;
    if (kind !== this.kind) this._build(kind);
    if (!this.gui) return;
    for (const [key, c] of this.controllers) {
      if (!force && this.pending.has(key)) continue;
      const v = modelValue(model, key);
      if (v !== undefined) this.values[key] = v;
      c.updateDisplay();
      c.enable(this.state.canEdit);
    }
  }
}
