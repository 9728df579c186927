import { Command } from './Command.js';

/**
 * The fold slider (composite sessions): pull every crease towards `amount` (0 flat … 1 the
 * design's fold angles) of its fold-angle target; the server streams iterates like a drag (latest
 * wins). The first fold message of a gesture is one undo step.
 */
export class FoldCommand extends Command {
  constructor(amount, options) {
    super('fold', options);
    if (typeof amount !== 'number' || !Number.isFinite(amount) || amount < 0 || amount > 1) {
      throw new TypeError('amount: expected a number in [0, 1]');
    }
    this.amount = amount;
    this.name = `fold to ${Math.round(amount * 100)} %`;
  }

  fields() {
    return { amount: this.amount };
  }
}

/** The slider let go or paused: release iterations settle the design at the last amount. */
export class FoldEndCommand extends Command {
  constructor(options) {
    super('fold_end', options);
    this.name = 'fold settles';
  }

  fields() {
    return {};
  }
}
