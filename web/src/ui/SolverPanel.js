// Solver settings (lil-gui). Each change is a SetSolverCommand; the control shows "pending"
// until the server acks it; an error reverts the control to the server's value and is shown
// right under it.

import GUI from 'lil-gui';
import { SetSolverCommand } from '../commands/SetSolverCommand.js';
import { describeError } from './Toast.js';
import { PendingControls } from './PendingControls.js';

// [key, label, kind, options]; kind: 'solver' (scene solver object) or 'session' (drag settings)
const FIELDS = [
  ['fairness', 'fairness', 'solver', { min: 0, step: 0.001 }],
  ['fairness_decay', 'fairness decay', 'solver', { min: 0.05, max: 1, step: 0.01 }],
  ['regularization', 'regularization', 'solver', { min: 0, step: 0.0005 }],
  ['unit_normal_weight', 'unit-normal weight', 'solver', { min: 0, step: 0.01 }],
  ['developability_weight', 'developability weight', 'solver', { min: 0, step: 0.1 }],
  ['handle_weight', 'handle weight', 'solver', { min: 0, step: 0.1 }],
  ['drag_iterations', 'iterations per drag (at most)', 'session', { min: 1, max: 100, step: 1 }],
  ['release_iterations', 'iterations on release (at most)', 'session', { min: 0, max: 1000, step: 1 }],
];

const DEFAULTS = {
  fairness: 0.01, fairness_decay: 0.8, regularization: 0.01, unit_normal_weight: 0.1,
  developability_weight: 1, handle_weight: 1, drag_iterations: 20, release_iterations: 200,
};

/**
 * Why `text`, typed into a number field, is not a value for it (null: it is one): not a number,
 * not finite, out of [min, max], or not a whole number where one is wanted.
 */
export function typedNumberProblem(text, { min, max, integer = false } = {}) {
  const t = String(text).trim();
  if (t === '' || !/^[-+]?(\d+\.?\d*|\.\d+)(e[-+]?\d+)?$/i.test(t)) return 'enter a number';
  const v = Number(t);
  if (!Number.isFinite(v)) return 'enter a finite number';
  if (min !== undefined && v < min) return `at least ${min}`;
  if (max !== undefined && v > max) return `at most ${max}`;
  if (integer && !Number.isInteger(v)) return 'enter a whole number';
  return null;
}

export class SolverPanel {
  constructor(parent, { state, send, errorSlots }) {
    this.state = state;
    this.send = send;
    this.params = { ...DEFAULTS };
    this.controllers = new Map();
    this.errorSlots = errorSlots;
    this.refused = new Map();  // key → why the text last typed into its field was not taken
    this.pending = new PendingControls('set_solver', 'solver:', (key) => this.controllers.get(key));
    this.gui = new GUI({ container: parent, title: 'Solver' });
    this.gui.domElement.classList.add('solver-gui');
    for (const [key, label, kind, o] of FIELDS) {
      const c = o.max !== undefined ? this.gui.add(this.params, key, o.min, o.max, o.step) : this.gui.add(this.params, key).min(o.min).step(o.step);
      c.name(label);
      c.domElement.dataset.setting = key;
      c.onFinishChange((value) => this._changed(key, kind, value));
      // lil-gui ignores text that is not a number and clamps to the range without a word: say why a
      // typed value is not taken (its 'change' comes before lil-gui's own finish on blur/Enter).
      if (c.$input) c.$input.addEventListener('change', () => this._checkTyped(key, label, { ...o, integer: kind === 'session' }, c.$input.value));
      const slot = errorSlots.slot(`solver:${key}`);
      c.domElement.after(slot);
      this.controllers.set(key, c);
    }
    // Normal representation (000_… §2.2): free vectors per parameter, or a normal spline. A
    // composite has one per face (one control point per curve control point): the solver's
    // normal_splines setting.
    this.normals = { normals: 'vectors', 'spline points': 8 };
    const normalsChanged = () => {
      const spline = this.normals.normals === 'spline';
      if (this._isComposite()) {
        const op = this.send(new SetSolverCommand({ normal_splines: spline }, {}, { source: 'solver:normals' }));
        if (op !== null && op !== undefined) this.pending.sent('normals');
        return;
      }
      const command = new SetSolverCommand({}, {
        normals: spline ? { type: 'spline', degree: 3, points: Math.round(this.normals['spline points']) } : { type: 'vectors' },
      }, { source: 'solver:normals' });
      const op = this.send(command);
      if (op !== null && op !== undefined) this.pending.sent('normals');
    };
    this.normalsType = this.gui.add(this.normals, 'normals', ['vectors', 'spline']).onFinishChange(normalsChanged);
    this.normalsType.domElement.dataset.setting = 'normals';
    this.normalsPoints = this.gui.add(this.normals, 'spline points', 4, 200, 1).onFinishChange(normalsChanged);
    this.normalsType.domElement.after(errorSlots.slot('solver:normals'));
    this.controllers.set('normals', this.normalsType);
    // A composite's development (000_… §5): solved with the surface, or apart from it (faster on
    // large designs; see the scene schema's development_solve).
    this.development = { development: 'coupled' };
    this.developmentSolve = this.gui.add(this.development, 'development', { 'with the surface': 'coupled', 'apart (faster)': 'alternating' })
      .onFinishChange((value) => {
        const op = this.send(new SetSolverCommand({ development_solve: value }, {}, { source: 'solver:development_solve' }));
        if (op === null || op === undefined) this.refresh(true);
        else this.pending.sent('development_solve');
      });
    this.developmentSolve.domElement.dataset.setting = 'development_solve';
    this.developmentSolve.domElement.after(errorSlots.slot('solver:development_solve'));
    this.controllers.set('development_solve', this.developmentSolve);
    state.on('scene', () => this.refresh());
    state.on('settings', () => this.refresh());
    state.on('session', () => this.refresh());
    state.on('editable', () => this.refresh());
    state.on('ack', ({ command }) => this._settled(command, null));
    state.on('error', ({ command, message }) => this._settled(command, message));
    this.refresh();
  }

  _isComposite() {
    const model = this.state.scene && this.state.scene.model;
    return !!model && model.kind === 'composite';
  }

  /** Checks the text typed into `key`'s field; a refused one is shown under it and not sent. */
  _checkTyped(key, label, { min, max, integer }, text) {
    const why = typedNumberProblem(text, { min, max, integer });
    if (why) {
      this.refused.set(key, why);
      this.errorSlots.show(`solver:${key}`, `${label}: ${why}`);
      this.refresh(true);  // back to the server's value
      return;
    }
    this.refused.delete(key);
    this.errorSlots.clear(`solver:${key}`);
  }

  _changed(key, kind, value) {
    if (this.refused.has(key) || typeof value !== 'number' || !Number.isFinite(value)) {
      // The finish of a refused text (lil-gui's clamp) is not sent; the refusal is spent, so the
      // slider moved next is taken.
      this.refused.delete(key);
      this.refresh(true);
      return;
    }
    const command = kind === 'solver'
      ? new SetSolverCommand({ [key]: value }, {}, { source: `solver:${key}` })
      : new SetSolverCommand({}, { [key]: Math.round(value) }, { source: `solver:${key}` });
    const op = this.send(command);
    if (op === null || op === undefined) {
      this.refresh(true);
      return;
    }
    this.pending.sent(key);
  }

  _settled(command, error) {
    if (this.pending.settled(command) === null) return;
    if (error) {
      // Back to the server's value; the message shows under the control (ErrorSlots).
      this.refresh(true);
      this.lastError = describeError(error);
    }
  }

  /** Shows the server's values (controls with a change in flight keep the user's value). */
  refresh(force = false) {
    const solver = (this.state.scene && this.state.scene.solver) || {};
    const settings = this.state.settings || {};
    for (const [key, , kind] of FIELDS) {
      if (!force && this.pending.has(key)) continue;
      const v = kind === 'solver' ? solver[key] : settings[key];
      if (typeof v === 'number') this.params[key] = v;
    }
    const normals = this.state.scene && this.state.scene.model && this.state.scene.model.normals;
    if (this._isComposite() && (force || !this.pending.has('normals'))) {
      this.normals.normals = solver.normal_splines === true ? 'spline' : 'vectors';
    } else if (normals && (force || !this.pending.has('normals'))) {
      this.normals.normals = normals.type === 'spline' ? 'spline' : 'vectors';
      if (normals.type === 'spline' && typeof normals.points === 'number') this.normals['spline points'] = normals.points;
    }
    if (force || !this.pending.has('development_solve'))
      this.development.development = solver.development_solve === 'alternating' ? 'alternating' : 'coupled';
    const model = this.state.scene && this.state.scene.model;
    this.developmentSolve.show(this._isComposite() && !!model.development);
    for (const c of this.controllers.values()) c.updateDisplay();
    const editable = this.state.canEdit;
    for (const c of this.controllers.values()) c.enable(editable);
    if (this.normalsPoints) {
      this.normalsPoints.updateDisplay();
      // A composite's normal splines have one control point per curve control point.
      this.normalsPoints.enable(editable && this.normals.normals === 'spline' && !this._isComposite());
    }
  }
}
