import { Command, point3, target, targetLabel } from './Command.js';

/** Add (or change) a permanent handle pulling a control point towards `position`. */
export class AddHandleCommand extends Command {
  constructor(t, position, weight, options) {
    super('add_handle', options);
    this.target = target(t);
    this.position = point3(position);
    if (weight !== undefined && weight !== null) {
      if (!(typeof weight === 'number' && weight > 0)) throw new TypeError('weight: must be > 0');
      this.weight = weight;
    }
    this.name = `add handle ${targetLabel(this.target)}`;
  }

  fields() {
    return { target: { ...this.target }, position: this.position.slice(), weight: this.weight };
  }
}
