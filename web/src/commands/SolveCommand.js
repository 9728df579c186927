import { Command } from './Command.js';

/** Run solver iterations (default 10), then `solved`. */
export class SolveCommand extends Command {
  constructor(iterations = 10, options) {
    super('solve', options);
    if (!Number.isInteger(iterations) || iterations < 1) throw new TypeError('iterations: expected an integer ≥ 1');
    this.iterations = iterations;
    this.name = `solve ${iterations}`;
  }

  fields() {
    return { iterations: this.iterations };
  }
}
