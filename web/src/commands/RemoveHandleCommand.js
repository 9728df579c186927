import { Command, target, targetLabel } from './Command.js';

/** Remove the permanent handle of a control point. */
export class RemoveHandleCommand extends Command {
  constructor(t, options) {
    super('remove_handle', options);
    this.target = target(t);
    this.name = `remove handle ${targetLabel(this.target)}`;
  }

  fields() {
    return { target: { ...this.target } };
  }
}
