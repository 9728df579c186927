import { Command, point3, target, targetLabel } from './Command.js';

/** Pull a control point towards `position` while dragging (drag_iterations follow). */
export class DragCommand extends Command {
  constructor(t, position, options) {
    super('drag', options);
    this.target = target(t);
    this.position = point3(position);
    this.name = `drag ${targetLabel(this.target)}`;
  }

  fields() {
    return { target: { ...this.target }, position: this.position.slice() };
  }
}
