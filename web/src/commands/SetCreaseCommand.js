import { Command } from './Command.js';

/** The conditions an interior edge of a composite can carry (scene `crease`). */
export const CREASE_KINDS = ['none', 'fold', 'geodesic', 'smooth'];

/** Composite sessions: switch the condition along interior edge `edge` (a structural, undoable edit). */
export class SetCreaseCommand extends Command {
  constructor(edge, crease, options) {
    super('set_crease', options);
    if (!Number.isInteger(edge) || edge < 0) throw new TypeError('edge: expected an integer ≥ 0');
    if (!CREASE_KINDS.includes(crease)) throw new TypeError(`crease: expected one of ${CREASE_KINDS.join(', ')}`);
    this.edge = edge;
    this.crease = crease;
    this.name = `crease of edge ${edge} → ${crease}`;
  }

  fields() {
    return { edge: this.edge, crease: this.crease };
  }
}
