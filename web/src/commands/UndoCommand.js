import { Command } from './Command.js';

/** Server-side undo (the history is the session's, shared by every participant). */
export class UndoCommand extends Command {
  constructor(options) {
    super('undo', options);
    this.name = 'undo';
  }
}
