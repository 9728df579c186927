import { Command } from './Command.js';
import { checkCrease } from './DrawCreaseCommand.js';

/** Removes drawn stroke `crease` (not an outline stroke). */
export class EraseCreaseCommand extends Command {
  constructor(crease, options) {
    super('erase_crease', options);
    this.crease = checkCrease(crease);
    this.name = `erase crease ${crease}`;
  }

  fields() {
    return { crease: this.crease };
  }
}
