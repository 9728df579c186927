import { Command } from './Command.js';

function edgeAndIndex(edge, index, minIndex) {
  if (!Number.isInteger(edge) || edge < 0) throw new TypeError('edge: expected an integer ≥ 0');
  if (!Number.isInteger(index) || index < minIndex) throw new TypeError(`index: expected an integer ≥ ${minIndex}`);
}

/**
 * Composite sessions: a new control point between points `index` and `index + 1` of S edge `edge`
 * (a knot inserted into every S edge sharing its spline space; the curves do not move).
 */
export class AddControlPointCommand extends Command {
  constructor(edge, index, options) {
    super('add_control_point', options);
    edgeAndIndex(edge, index, 0);
    this.edge = edge;
    this.index = index;
    this.name = `add a control point to edge ${edge} after point ${index}`;
  }

  fields() {
    return { edge: this.edge, index: this.index };
  }
}

/**
 * Composite sessions: removes interior control point `index` of S edge `edge` (a knot out of every
 * S edge sharing its spline space, the curves approximated, then a solve).
 */
export class RemoveControlPointCommand extends Command {
  constructor(edge, index, options) {
    super('remove_control_point', options);
    edgeAndIndex(edge, index, 1);
    this.edge = edge;
    this.index = index;
    this.name = `remove control point ${index} of edge ${edge}`;
  }

  fields() {
    return { edge: this.edge, index: this.index };
  }
}
