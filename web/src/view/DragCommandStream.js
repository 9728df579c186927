// The drag messages of one pointer drag, shared by the 3D view and the unfolding: positions given
// while dragging are sent at most once per animation frame — one DragCommand with the latest
// position (latest wins) — and the end of the drag sends what is still pending, then a
// DragEndCommand when the point moved at all.

import { DragCommand } from '../commands/DragCommand.js';
import { DragEndCommand } from '../commands/DragEndCommand.js';

export class DragCommandStream {
  /**
   * @param {(command) => void} send
   * @param {object} target  the dragged point target
   * @param {string} source  the view that drags ('viewport' | 'unfolding'), passed to the commands
   */
  constructor(send, target, source) {
    this.send = send;
    this.target = target;
    this.source = source;
    this.pending = null;
    this.raf = 0;
    this.moved = false;
  }

  /** Queues the latest position [x, y, z]; it is sent at the next animation frame. */
  move(position) {
    this.pending = position;
    this.moved = true;
    if (!this.raf) this.raf = requestAnimationFrame(() => this.flush());
  }

  /** Sends the pending position now, if any. */
  flush() {
    this.raf = 0;
    if (!this.pending) return;
    const p = this.pending;
    this.pending = null;
    this.send(new DragCommand(this.target, p, { source: this.source }));
  }

  /**
   * Drops the drag without a word to the server (the connection went away: nothing could be
   * sent, and the resync shows where the point is); later moves and the end send nothing.
   */
  abandon() {
    if (this.raf) cancelAnimationFrame(this.raf);
    this.raf = 0;
    this.pending = null;
    this.moved = false;
    this.send = () => {};
  }

  /** Ends the drag: the pending position, then DragEndCommand when anything moved. */
  end() {
    if (this.raf) cancelAnimationFrame(this.raf);
    this.raf = 0;
    if (this.pending) this.flush();
    if (this.moved) this.send(new DragEndCommand(this.target, undefined, { source: this.source }));
  }
}
