// Commands in flight per control of a settings panel (solver settings, strip parameters): the
// control is marked "pending" from send until the server acks or rejects the last of them, and
// the panel's refresh leaves a pending control's value alone.

export class PendingControls {
  /**
   * @param {string} type    command type the panel sends ('set_solver', 'set_params')
   * @param {string} prefix  source prefix of its commands ('solver:' → source 'solver:<key>')
   * @param {(key: string) => object|undefined} controllerOf  the lil-gui controller of a key
   */
  constructor(type, prefix, controllerOf) {
    this.type = type;
    this.prefix = prefix;
    this.controllerOf = controllerOf;
    this.counts = new Map(); // key → number of commands in flight
  }

  has(key) { return this.counts.has(key); }

  clear() { this.counts.clear(); }

  /** A command for `key` was sent. */
  sent(key) {
    this.counts.set(key, (this.counts.get(key) || 0) + 1);
    const c = this.controllerOf(key);
    if (c) c.domElement.classList.add('pending');
  }

  /** An ack or error arrived for `command`: returns its key if it was one of ours, else null. */
  settled(command) {
    if (!command || command.type !== this.type || !command.source || !command.source.startsWith(this.prefix)) return null;
    const key = command.source.slice(this.prefix.length);
    const n = (this.counts.get(key) || 1) - 1;
    if (n <= 0) {
      this.counts.delete(key);
      const c = this.controllerOf(key);
      if (c) c.domElement.classList.remove('pending');
    } else {
      this.counts.set(key, n);
    }
    return key;
  }
}
