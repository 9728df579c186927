import { Command, target } from './Command.js';

/** What this participant has selected (null = nothing), and optionally its display name. */
export class PresenceCommand extends Command {
  constructor(selection, name, options) {
    super('presence', options);
    this.selection = selection ? target(selection) : null;
    if (name !== undefined && name !== null) this.displayName = String(name).slice(0, 40);
    this.name = 'presence';
  }

  fields() {
    return { selection: this.selection ? { ...this.selection } : null, name: this.displayName };
  }
}
