// The Selection panel's curve-point buttons (composites; issue 16 item 3): with a control point of
// an S edge selected, insert a point after it (the curve does not move: a knot goes into every
// curve sharing its spline space) or remove it (the curves are approximated, then solved).

import { h } from './dom.js';
import { AddControlPointCommand, RemoveControlPointCommand } from '../commands/ControlPointCommands.js';

const SOURCE = 'selection:curve-point';

/** The S-edge control point a selection names ({edge, index} with an interior index), or null. */
export function curvePointOf(selection) {
  if (!selection || !Number.isInteger(selection.edge) || !Number.isInteger(selection.index)) return null;
  return selection.index >= 1 ? { edge: selection.edge, index: selection.index } : null;
}

export class CurvePointControls {
  /**
   * @param {HTMLElement} parent  the Selection panel's section
   * @param {object} deps {state, send(command), errorSlots}
   */
  constructor(parent, { state, send, errorSlots }) {
    this.state = state;
    this.addButton = h('button', {
      class: 'btn small', testid: 'curve-point-add',
      title: 'Insert a control point after this one (the curve does not move; the curves sharing its spline space get one too)',
      onclick: () => this.apply(AddControlPointCommand),
    }, 'Insert point after');
    this.removeButton = h('button', {
      class: 'btn small', testid: 'curve-point-remove',
      title: 'Remove this control point (the curves sharing its spline space lose one; they are approximated and solved)',
      onclick: () => this.apply(RemoveControlPointCommand),
    }, 'Remove point');
    this.root = h('div', { class: 'row curve-points', testid: 'curve-points', hidden: true },
      h('span', { class: 'muted small' }, 'curve'), this.addButton, this.removeButton, errorSlots.slot(SOURCE));
    this.send = send;
    this.errorSlots = errorSlots;
    parent.appendChild(this.root);
    for (const ev of ['selection', 'scene', 'session', 'editable']) state.on(ev, () => this.render());
    this.render();
  }

  apply(CommandClass) {
    const point = curvePointOf(this.state.selection);
    if (!point) return;
    this.errorSlots.clear(SOURCE);
    this.send(new CommandClass(point.edge, point.index, { source: SOURCE }));
  }

  render() {
    const point = this.state.kind === 'composite' ? curvePointOf(this.state.selection) : null;
    this.root.hidden = !point;
    const editable = this.state.canEdit;
    this.addButton.disabled = !editable;
    this.removeButton.disabled = !editable;
  }
}
