import { Command } from './Command.js';

/** Join a session (sent by ProtocolClient on every (re)connect). */
export class JoinCommand extends Command {
  constructor(session, token, name, options) {
    super('join', options);
    this.session = String(session);
    this.token = String(token);
    if (name) this.displayName = String(name).slice(0, 40);
  }

  fields() {
    return { session: this.session, token: this.token, name: this.displayName };
  }
}

/** Round trip: {"type":"pong","op","seq"}. */
export class PingCommand extends Command {
  constructor(options) {
    super('ping', options);
  }
}
