import { Command, target, targetLabel } from './Command.js';

/** Fix or free a control point. */
export class SetFixedCommand extends Command {
  constructor(t, fixed, options) {
    super('set_fixed', options);
    this.target = target(t);
    this.fixed = !!fixed;
    this.name = `${this.fixed ? 'fix' : 'free'} ${targetLabel(this.target)}`;
  }

  fields() {
    return { target: { ...this.target }, fixed: this.fixed };
  }
}
