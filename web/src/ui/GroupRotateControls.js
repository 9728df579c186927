// The Selection panel's rotate controls (composites; issue 16 item 3, 000_… §4.1 Fig. 8 bottom
// row): how many points the group holds (Shift/Ctrl-click adds or removes one; a single selected
// point is a group of one), the axis (X, Y, Z or the viewing direction), the centre (the group's
// centroid unless typed), the angle and the solve after the turn; Rotate (R, Shift+R the other
// way) sends a RotatePointsCommand.

import { h } from './dom.js';
import { DEFAULT_ROTATE_ANGLE, ROTATE_AXES, centroid, rotateCommandFrom } from '../geometry/groupRotation.js';
import { targetKey } from '../commands/Command.js';

const SOURCE = 'selection:rotate';
const fmt = (x) => String(Number(x.toFixed(4)));

export class GroupRotateControls {
  /**
   * @param {HTMLElement} parent  the Selection panel's section (the controls go before `before`)
   * @param {object} deps {state, pointOf(target) → [x,y,z]|null, send(command), errorSlots,
   *   viewDirection() → [x,y,z] (the camera's), clearGroup(), before?: HTMLElement}
   */
  constructor(parent, { state, pointOf, send, errorSlots, viewDirection, clearGroup, before = null }) {
    this.state = state;
    this.pointOf = pointOf;
    this.send = send;
    this.errorSlots = errorSlots;
    this.viewDirection = viewDirection;
    this.count = h('span', { class: 'group-count', testid: 'group-count' });
    this.clearButton = h('button', { class: 'btn small', testid: 'group-clear', title: 'Clear the group selection (Esc)', onclick: clearGroup }, 'Clear');
    this.axisButtons = ROTATE_AXES.map((a) => h('button', {
      class: 'btn small axis-btn', testid: `rotate-axis-${a}`, 'aria-pressed': 'false',
      title: a === 'view' ? 'Turn about the viewing direction (counter-clockwise on screen for a positive angle)' : `Turn about the ${a} axis (counter-clockwise looking down it)`,
      onclick: () => state.setRotateAxis(a),
    }, a === 'view' ? 'view' : a.toUpperCase()));
    // The centre: the group's centroid, or typed (kept until the group changes or ↺).
    this.centreInputs = ['x', 'y', 'z'].map((axis) => h('input', {
      type: 'number', step: 'any', class: 'coord-input', testid: `rotate-centre-${axis}`, 'aria-label': `${axis} of the rotation centre`,
      oninput: () => { this.centreTyped = true; this._typedCentre(); },
      onkeydown: (e) => { if (e.key === 'Enter') this.rotate(); },
    }));
    this.centreReset = h('button', { class: 'btn small', testid: 'rotate-centre-reset', title: 'Back to the centroid of the group', 'aria-label': 'Centre at the centroid',
      onclick: () => { this._untypeCentre(); this.render(); } }, '↺');
    this.centreNote = h('span', { class: 'muted small' });
    this.angle = h('input', {
      type: 'number', step: 'any', min: '-360', max: '360', value: String(DEFAULT_ROTATE_ANGLE), class: 'coord-input', testid: 'rotate-angle',
      'aria-label': 'Rotation angle in degrees', onkeydown: (e) => { if (e.key === 'Enter') this.rotate(); },
    });
    this.iterations = h('input', {
      type: 'number', step: '1', min: '0', max: '1000', placeholder: 'auto', class: 'coord-input', testid: 'rotate-iterations',
      'aria-label': 'Solver iterations after the turn', title: 'Solver iterations after the turn (blank: the session\'s release iterations; 0: turn only)',
    });
    this.rotateButton = h('button', { class: 'btn', testid: 'rotate-group', title: 'Turn the group by the angle about the axis through the centre (R; Shift+R the other way), then solve', onclick: () => this.rotate() }, 'Rotate');
    this.root = h('div', { class: 'group-rotate', testid: 'group-rotate', hidden: true },
      h('div', { class: 'row group-head' }, h('span', { class: 'sel-title' }, 'Rotate group'), this.count, this.clearButton),
      h('div', { class: 'row group-axes' }, h('span', { class: 'muted small' }, 'axis'), ...this.axisButtons),
      h('div', { class: 'row coord-row' }, h('span', { class: 'muted small' }, 'centre'),
        ...this.centreInputs.flatMap((input, k) => [h('span', { class: 'muted small' }, 'xyz'[k]), input])),
      h('div', { class: 'row group-centre-note' }, this.centreNote, this.centreReset),
      h('div', { class: 'row coord-row' },
        h('label', { class: 'small row group-field' }, h('span', { class: 'muted' }, 'angle °'), this.angle),
        h('label', { class: 'small row group-field' }, h('span', { class: 'muted' }, 'solve'), this.iterations),
        this.rotateButton),
      errorSlots.slot(SOURCE),
      h('p', { class: 'muted small' }, 'Shift+click (or Ctrl/⌘+click) points to add or remove them; Esc clears. The solver makes the design developable again near the turned shape.'));
    parent.insertBefore(this.root, before && before.parentNode === parent ? before : null);
    this.centreTyped = false;
    this._groupKey = '';
    for (const ev of ['group', 'selection', 'rotate-axis', 'scene', 'session', 'iterate', 'editable']) state.on(ev, () => this.render());
    this.render();
  }

  /** Whether the controls are shown (a composite with a group, in an editing session). */
  get visible() {
    return !this.root.hidden;
  }

  /** The points the rotation turns (those the view knows). */
  targets() {
    return this.state.rotationTargets().filter((t) => this.pointOf(t));
  }

  render() {
    const st = this.state;
    const targets = st.kind === 'composite' ? this.targets() : [];
    this.root.hidden = targets.length === 0;
    if (this.root.hidden) return;
    const n = targets.length;
    this.count.textContent = `${n} point${n === 1 ? '' : 's'} selected`;
    this.clearButton.hidden = st.group.length === 0;
    const key = targets.map(targetKey).join(' ');
    if (key !== this._groupKey) {
      // Another group: the centre follows its centroid again.
      this._groupKey = key;
      this._untypeCentre();
    }
    for (const b of this.axisButtons) b.setAttribute('aria-pressed', String(b.dataset.testid === `rotate-axis-${st.rotateAxis}`));
    const c = centroid(targets.map((t) => this.pointOf(t)));
    this.centroid = c;
    if (!this.centreTyped && c) {
      this.centreInputs.forEach((input, k) => {
        if (document.activeElement !== input) input.value = fmt(c[k]);
      });
    }
    this._renderCentreNote();
    const editable = st.canEdit;
    for (const el of [...this.axisButtons, ...this.centreInputs, this.centreReset, this.angle, this.iterations, this.rotateButton]) el.disabled = !editable;
  }

  /** The typed centre goes to the state (the 3D view marks it) once all three are numbers. */
  _typedCentre() {
    const c = this.centreInputs.map((input) => (input.value.trim() === '' ? NaN : Number(input.value)));
    this.state.setRotateCentre(c.every(Number.isFinite) ? c : null);
    this._renderCentreNote();
  }

  _untypeCentre() {
    this.centreTyped = false;
    this.state.setRotateCentre(null);
  }

  _renderCentreNote() {
    this.centreNote.textContent = this.centreTyped ? 'typed centre' : 'the centroid of the group';
    this.centreReset.hidden = !this.centreTyped;
  }

  /**
   * Sends the turn (sign −1: the other way). Returns false (and shows why next to the controls)
   * when the inputs are not a valid rotation.
   */
  rotate(sign = 1) {
    if (!this.visible || !this.state.canEdit) return false;
    const angleText = sign < 0 && this.angle.value.trim() !== '' ? String(-Number(this.angle.value)) : this.angle.value;
    const { command, error } = rotateCommandFrom({
      targets: this.targets(),
      axis: this.state.rotateAxis,
      viewDirection: this.state.rotateAxis === 'view' ? this.viewDirection() : null,
      angle: angleText,
      centre: this.centreTyped ? this.centreInputs.map((input) => input.value) : null,
      iterations: this.iterations.value,
      source: SOURCE,
    });
    if (error) {
      this.errorSlots.show(SOURCE, error.message);
      return false;
    }
    this.errorSlots.clear(SOURCE);
    this.send(command);
    return true;
  }
}
