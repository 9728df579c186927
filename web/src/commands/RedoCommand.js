import { Command } from './Command.js';

/** Server-side redo. */
export class RedoCommand extends Command {
  constructor(options) {
    super('redo', options);
    this.name = 'redo';
  }
}
