import { Command } from './Command.js';

/**
 * Solve: without a count the server iterates until every hard row is within its tolerance (or
 * its time budget ends) and answers `solved` with the quality verdict; with one, at most that
 * many iterations.
 */
export class SolveCommand extends Command {
  constructor(iterations = undefined, options) {
    super('solve', options);
    if (iterations !== undefined && (!Number.isInteger(iterations) || iterations < 1)) {
      throw new TypeError('iterations: expected an integer ≥ 1');
    }
    this.iterations = iterations;
    this.name = iterations === undefined ? 'solve' : `solve ${iterations}`;
  }

  fields() {
    return this.iterations === undefined ? {} : { iterations: this.iterations };
  }
}
