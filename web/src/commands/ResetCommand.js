import { Command } from './Command.js';

/** Back to the scene the session was created with (undoable). */
export class ResetCommand extends Command {
  constructor(options) {
    super('reset', options);
    this.name = 'reset';
  }
}
