import { Command, target, targetLabel } from './Command.js';

/** Release a dragged control point: release_iterations follow, then `solved`. */
export class DragEndCommand extends Command {
  constructor(t, iterations, options) {
    super('drag_end', options);
    this.target = target(t);
    if (iterations !== undefined && iterations !== null) {
      if (!Number.isInteger(iterations) || iterations < 0) throw new TypeError('iterations: expected an integer ≥ 0');
      this.iterations = iterations;
    }
    this.name = `release ${targetLabel(this.target)}`;
  }

  fields() {
    return { target: { ...this.target }, iterations: this.iterations };
  }
}
