// WebSocket client of the devsurf protocol (docs/protocol.md).
//
// - join on every (re)connect; the `state` answer is a full resync of the editor state;
// - every command gets an op id; ack/error messages are matched to their command by op;
// - on an unexpected close: reconnect with exponential back-off (250 ms, 500 ms, … capped at 8 s),
//   reset after a successful join; commands still pending when the connection drops fail with a
//   local `disconnected` error (their outcome is unknown: the resync shows the truth);
// - `unauthorized` (bad token or unknown session) and `quarantined` (a session a restart could
//   not restore) are final: the state goes `offline`.
// The connection state is kept in the editor state (`connection`).

import { JoinCommand } from '../commands/JoinCommand.js';

/** The messages a view-only connection may send (server/src/Session.cpp: the others edit). */
const VIEWER_MESSAGES = new Set(['presence', 'ping', 'join']);

export const BACKOFF_INITIAL_MS = 250;
export const BACKOFF_MAX_MS = 8000;

/** Delay before reconnect attempt number `attempt` (0-based): 250 ms · 2^attempt, at most 8 s. */
export function backoffDelay(attempt, initial = BACKOFF_INITIAL_MS, max = BACKOFF_MAX_MS) {
  return Math.min(max, initial * Math.pow(2, attempt));
}

/**
 * A connection opened and joined before the editor's code has loaded (main.js): the join goes out
 * as soon as the socket opens and what the server answers is kept until ProtocolClient.connect
 * takes the connection over, so the session's state is on its way while the editor is built.
 * Returns {socket, queued: MessageEvent[], joinSent()}; throws when no WebSocket can be made.
 */
export function openEarlyJoin(url, session, token, name, WebSocketImpl = globalThis.WebSocket) {
  const socket = new WebSocketImpl(sessionSocketUrl(url, session));
  const queued = [];
  let sent = false;
  const mark = (name) => globalThis.performance && performance.mark && performance.mark(name);
  socket.onopen = () => {
    socket.send(JSON.stringify(new JoinCommand(session, token, name).toMessage()));
    sent = true;
    mark('devsurf:join-sent');
  };
  socket.onmessage = (event) => {
    if (!queued.length) mark('devsurf:first-answer');
    queued.push(event);
  };
  return { socket, queued, joinSent: () => sent };
}

/** ws:// or wss:// URL of the daemon's /ws on the page's host. */
export function defaultSocketUrl(loc = globalThis.location) {
  const proto = loc.protocol === 'https:' ? 'wss:' : 'ws:';
  return `${proto}//${loc.host}/ws`;
}

/**
 * The socket URL for one session: `?session=ID` names it in the URL, so a proxy in front of
 * several daemons (docs/scaling.md) routes every connection of a session to the daemon that
 * holds it. The daemon reads the session from the join message; the parameter is for the proxy.
 */
export function sessionSocketUrl(url, session) {
  if (!session) return url;
  return `${url}${url.includes('?') ? '&' : '?'}session=${encodeURIComponent(session)}`;
}

const OPEN = 1;

export class ProtocolClient {
  /**
   * @param {object} options
   *   url, state (EditorState), WebSocketImpl (default globalThis.WebSocket),
   *   timers {setTimeout, clearTimeout}, backoff {initial, max}, now () => ms
   */
  constructor(options) {
    this.url = options.url;
    this.state = options.state;
    this.WebSocketImpl = options.WebSocketImpl || globalThis.WebSocket;
    this.timers = options.timers || { setTimeout: (f, ms) => setTimeout(f, ms), clearTimeout: (t) => clearTimeout(t) };
    this.backoff = { initial: BACKOFF_INITIAL_MS, max: BACKOFF_MAX_MS, ...(options.backoff || {}) };
    this.now = options.now || (() => Date.now());
    this.ws = null;
    this.nextOp = 1;
    /** op → {command, message, sentAt} */
    this.pending = new Map();
    this.attempt = 0;
    this.joined = false;
    this.stopped = true;
    this.retryTimer = null;
    this.nextRetryAt = null;
    /** Delays (ms) of the reconnects scheduled so far (for tests and diagnostics). */
    this.scheduledDelays = [];
    this.joinInfo = null;
    /** The `unauthorized` or `quarantined` error that ended the connection for good, if any. */
    this.fatal = null;
    /** The last join was answered `unavailable`: the session is moving to another daemon. */
    this.moving = false;
  }

  /**
   * Opens the connection and joins `session` with `token` (role follows from the token).
   * `socket`: a WebSocket to this.url the page opened earlier (connecting or open, so the
   * handshake ran while the editor's code loaded), or an early join (openEarlyJoin: joined
   * already, its answers kept); used for the first attempt only.
   */
  connect(session, token, name, socket = null) {
    this.joinInfo = { session, token, name };
    this.stopped = false;
    this.fatal = null;
    this.attempt = 0;
    this.state.setConnection('connecting');
    this._open(socket);
  }

  /** Closes for good (no reconnect). */
  close() {
    this.stopped = true;
    this._clearRetry();
    const ws = this.ws;
    this.ws = null;
    if (ws) {
      ws.onopen = ws.onmessage = ws.onclose = ws.onerror = null;
      try { ws.close(1000, 'bye'); } catch { /* ignore */ }
    }
    this._failPending('closed', 'The connection was closed.');
    this.joined = false;
    this.state.setConnection('offline');
  }

  /** Reconnects now (e.g. when the browser comes back online), skipping the back-off wait. */
  reconnectNow() {
    if (this.stopped || this.ws) return;
    this._clearRetry();
    this._open();
  }

  get connected() {
    return !!this.ws && this.joined && this.ws.readyState === OPEN;
  }

  /**
   * Sends a command. Returns its op id, or null if it could not be sent (not connected: a local
   * `offline` error is reported for it instead).
   */
  send(command) {
    if (!this.connected) {
      this.state.applyError({ type: 'error', code: 'offline', message: 'Not connected to the server: the action was not sent.' }, command);
      return null;
    }
    // A view-only link changes nothing: its edits (a keyboard shortcut, say) are not sent at all,
    // as the server would refuse them (Session: every type but presence, ping and join edits).
    if (this.state.role === 'view' && !VIEWER_MESSAGES.has(command.type)) {
      this.state.applyError({ type: 'error', code: 'forbidden',
        message: 'This link is view only: it cannot change the design (ask for the edit link).' }, command);
      return null;
    }
    const op = this.nextOp++;
    const message = command.toMessage(op);
    this.pending.set(op, { command, message, sentAt: this.now() });
    this.ws.send(JSON.stringify(message));
    return op;
  }

  _open(socket = null) {
    this.retryTimer = null;
    this.nextRetryAt = null;
    this.joined = false;
    // An early join (openEarlyJoin): its socket, the answers that came before this took over.
    const early = socket && socket.socket ? socket : null;
    if (early) socket = early.socket;
    let ws;
    try {
      // An early socket that already closed (its close event went unheard) is not used.
      ws = socket && socket.readyState <= OPEN ? socket
        : new this.WebSocketImpl(sessionSocketUrl(this.url, this.joinInfo && this.joinInfo.session));
    } catch (e) {
      this.ws = null;
      this._scheduleReconnect();
      return;
    }
    this.ws = ws;
    ws.onopen = () => {
      if (this.ws !== ws) return;
      const { session, token, name } = this.joinInfo;
      ws.send(JSON.stringify(new JoinCommand(session, token, name).toMessage()));
    };
    ws.onmessage = (event) => {
      if (this.ws !== ws) return;
      let msg;
      try {
        msg = JSON.parse(typeof event.data === 'string' ? event.data : String(event.data));
      } catch {
        return;
      }
      this._onMessage(msg);
    };
    ws.onerror = () => { /* a close follows */ };
    ws.onclose = (event) => {
      if (this.ws !== ws) return;
      this._onClose(event || {});
    };
    if (early && ws === early.socket) {
      if (early.joinSent()) {
        // Joined already: hand on what the server has answered so far, in order.
        for (const event of early.queued.splice(0)) {
          if (this.ws !== ws) return;
          ws.onmessage(event);
        }
        return;
      }
      early.queued.length = 0;
    }
    if (ws.readyState === OPEN) ws.onopen();  // an early socket that is open already
  }

  _onMessage(msg) {
    switch (msg.type) {
      case 'state':
        this.joined = true;
        this.attempt = 0;
        this.state.applyServerMessage(msg);
        this.state.setConnection('connected');
        return;
      case 'ack': {
        const p = this.pending.get(msg.op);
        this.pending.delete(msg.op);
        this.state.applyAck(msg, p ? p.command : null);
        return;
      }
      case 'error': {
        const p = msg.op !== undefined ? this.pending.get(msg.op) : undefined;
        if (p) this.pending.delete(msg.op);
        // Several daemons (docs/scaling.md): the session is moving between them. The server closes
        // the socket and the reconnect finds it where it is now; nothing to show but the status.
        if (msg.code === 'unavailable' && !this.joined) {
          this.moving = true;
          return;
        }
        if (msg.code === 'unauthorized' || msg.code === 'quarantined') this.fatal = msg;
        this.state.applyError(msg, p ? p.command : null);
        return;
      }
      case 'pong': {
        this.pending.delete(msg.op);
        this.state.applyServerMessage(msg);
        return;
      }
      default:
        this.state.applyServerMessage(msg);
    }
  }

  _onClose(event) {
    this.ws = null;
    this.joined = false;
    this._failPending('disconnected', 'The connection dropped before the server answered.');
    if (this.stopped) {
      this.state.setConnection('offline');
      return;
    }
    if (this.fatal) {
      this.stopped = true;
      this.state.setConnection('offline', { reason: this.fatal.message });
      return;
    }
    this._scheduleReconnect(event);
  }

  _scheduleReconnect(event) {
    const delay = backoffDelay(this.attempt, this.backoff.initial, this.backoff.max);
    this.attempt++;
    this.scheduledDelays.push(delay);
    this.nextRetryAt = this.now() + delay;
    this.state.setConnection('reconnecting', { delay, attempt: this.attempt, code: event && event.code,
      moving: this.moving || (event && (event.code === 1012 || event.code === 1013)) || false });
    this.moving = false;
    this.retryTimer = this.timers.setTimeout(() => this._open(), delay);
  }

  _clearRetry() {
    if (this.retryTimer !== null) this.timers.clearTimeout(this.retryTimer);
    this.retryTimer = null;
    this.nextRetryAt = null;
  }

  _failPending(code, message) {
    if (this.pending.size === 0) return;
    const failed = [...this.pending.values()];
    this.pending.clear();
    for (const p of failed) {
      // Drags and presence are transient: their loss needs no message.
      if (['drag', 'presence', 'ping'].includes(p.command.type)) continue;
      this.state.applyError({ type: 'error', code, message, local: true }, p.command);
    }
  }
}
