// The editor's single state object: everything the UI shows is read from here, and every change
// is announced with a signal (`on(event, fn)` / `emit(event, data)`).
//
// Signals: connection, session (a fresh `state` after join or resync), scene (scene, constraints
// or settings changed), geometry ({geometry, source}), iterate (the iterate message), solved,
// metrics, presence, selection, group (the group selection of a composite), rotate-axis,
// editable (canEdit changed: an edit link joined and connected, or not),
// rotate-centre, undo,
// ack ({message, command}), error ({message, command}), settings, accessibility, change (after
// any of the above).

import { sameTarget, targetKey, targetOf } from '../commands/Command.js';

export const RESIDUAL_HISTORY_LIMIT = 400;

export class EditorState {
  constructor() {
    this._listeners = new Map();
    this.reset();
  }

  reset() {
    /** 'connected' | 'connecting' | 'reconnecting' | 'offline' */
    this.connection = 'offline';
    this.session = null;
    this.role = null;
    /** Our own participant id (from `state.you`). */
    this.you = null;
    this.seq = 0;
    this.metrics = null;
    this.participants = [];
    this.iterateCount = 0;
    this.lastError = null;
    this.scene = null;
    this.constraints = { fixed: [], handles: [] };
    this.settings = { drag_iterations: 20, release_iterations: 200 };
    this.undo = { available: 0, redo_available: 0 };
    this.selection = null;
    /**
     * Composites: the group selection (Shift/Ctrl-click), the points a rotate_points turns, in
     * the order picked. Empty: none (a single selected point then counts as a group of one).
     */
    this.group = [];
    /** The axis the Selection panel turns the group about: 'x' | 'y' | 'z' | 'view'. */
    this.rotateAxis = 'z';
    /** A typed centre of the turn [x, y, z], or null: the group's centroid. */
    this.rotateCentre = null;
    /** Composites: the interior edge selected for the crease panel (edge index) or null. */
    this.selectedEdge = null;
    /** 'strip' | 'composite' (the session's model kind, from its scene). */
    this.kind = 'strip';
    /** Last iterate: {iteration, time_ms, residuals, seq}. */
    this.lastIterate = null;
    /** Last `solved`: {reason, iterations, seq, quality}. */
    this.lastSolved = null;
    /**
     * The quality verdict of the state shown ({met, checks}), from the last `solved` or `update`
     * (an undo's update brings the verdict of the state it restores), or null.
     */
    this.quality = null;
    /** Residual history across solves: {x: number[], terms: {name: number[]}}. */
    this.residualHistory = { x: [], terms: {} };
    this.residualStep = 0;
    /** Tokens known for this session (edit/view), for the share links. */
    this.tokens = { edit: null, view: null };
    this.name = '';
  }

  on(event, fn) {
    if (!this._listeners.has(event)) this._listeners.set(event, new Set());
    this._listeners.get(event).add(fn);
    return () => this.off(event, fn);
  }

  off(event, fn) {
    const set = this._listeners.get(event);
    if (set) set.delete(fn);
  }

  emit(event, data) {
    const set = this._listeners.get(event);
    if (set) for (const fn of [...set]) fn(data, this);
    if (event !== 'change') {
      const all = this._listeners.get('change');
      if (all) for (const fn of [...all]) fn({ event, data }, this);
    }
  }

  // ---- local changes -------------------------------------------------------------------------

  /**
   * Whether this editor can send edits now: it joined with an edit link and is connected. Offline
   * or reconnecting, the controls that edit are disabled (an edit would not be sent) until the
   * resync; the 'editable' signal announces each change.
   */
  get canEdit() {
    return this.role === 'edit' && this.connection === 'connected';
  }

  _emitEditable(before) {
    if (this.canEdit !== before) this.emit('editable', this.canEdit);
  }

  setConnection(connection, detail) {
    if (this.connection === connection) return;
    const editable = this.canEdit;
    this.connection = connection;
    this.emit('connection', { connection, detail });
    this._emitEditable(editable);
  }

  setSelection(target) {
    if (this.selection === target || sameTarget(this.selection, target) || (!this.selection && !target)) return false;
    this.selection = target ? targetOf(target) : null;
    this.emit('selection', this.selection);
    return true;
  }

  /** Sets the group selection (targets; duplicates dropped). Signal: 'group'. */
  setGroup(targets) {
    const seen = new Set();
    const group = [];
    for (const t of targets || []) {
      const x = targetOf(t);
      const key = targetKey(x);
      if (!key || seen.has(key)) continue;
      seen.add(key);
      group.push(x);
    }
    if (group.length === this.group.length && group.every((t, k) => sameTarget(t, this.group[k]))) return false;
    this.group = group;
    this.emit('group', this.group);
    return true;
  }

  /**
   * Adds a point to the group selection, or removes it when it is in it (Shift/Ctrl-click). A
   * single selected point joins the group first; the selection follows the point just added (or
   * the last one left). Returns whether the point is in the group now.
   */
  toggleGroupMember(target) {
    const t = targetOf(target);
    if (!t) return false;
    const group = this.group.length || !this.selection ? this.group.slice() : [this.selection];
    const k = group.findIndex((x) => sameTarget(x, t));
    if (k >= 0) group.splice(k, 1);
    else group.push(t);
    this.setGroup(group);
    this.setSelection(k >= 0 ? (this.group.length ? this.group[this.group.length - 1] : null) : t);
    return k < 0;
  }

  /** Whether a point is in the group selection. */
  inGroup(target) {
    return this.group.some((t) => sameTarget(t, target));
  }

  /** Whether a point is one of the session's fixed points. */
  isFixed(target) {
    return !!(this.constraints && this.constraints.fixed.some((f) => sameTarget(f, target)));
  }

  /** The points a rotation turns: the group, or the single selected point, or none. */
  rotationTargets() {
    if (this.group.length) return this.group.map((t) => ({ ...t }));
    return this.selection ? [{ ...this.selection }] : [];
  }

  /** Signal: 'rotate-axis'. */
  setRotateAxis(axis) {
    if (axis === this.rotateAxis) return false;
    this.rotateAxis = axis;
    this.emit('rotate-axis', axis);
    return true;
  }

  /** A typed centre of the turn, or null for the centroid. Signal: 'rotate-centre'. */
  setRotateCentre(centre) {
    const c = Array.isArray(centre) && centre.length === 3 && centre.every(Number.isFinite) ? centre.slice() : null;
    const same = c === this.rotateCentre || (c && this.rotateCentre && c.every((x, k) => x === this.rotateCentre[k]));
    if (same) return false;
    this.rotateCentre = c;
    this.emit('rotate-centre', c);
    return true;
  }

  /** Selects an edge of a composite (index) or none (null). Signal: 'edge-selection'. */
  setSelectedEdge(edge) {
    const e = Number.isInteger(edge) && edge >= 0 ? edge : null;
    if (e === this.selectedEdge) return false;
    this.selectedEdge = e;
    this.emit('edge-selection', e);
    return true;
  }

  setTokens(tokens) {
    this.tokens = { ...this.tokens, ...tokens };
    this.emit('tokens', this.tokens);
  }

  // ---- server messages ------------------------------------------------------------------------

  /** Dispatches one server message (except ack/error, which ProtocolClient matches to commands). */
  applyServerMessage(msg) {
    switch (msg.type) {
      case 'state': return this.applyState(msg);
      case 'iterate': return this.applyIterate(msg);
      case 'solved': return this.applySolved(msg);
      case 'update': return this.applyUpdate(msg);
      case 'edit': return this.applyEdit(msg);
      case 'presence': return this.applyPresence(msg);
      case 'links': return msg.view_token ? this.setTokens({ view: msg.view_token }) : undefined;
      case 'pong': return this._seenSeq(msg.seq);
      default: return undefined;
    }
  }

  _seenSeq(seq) {
    if (Number.isInteger(seq) && seq > this.seq) this.seq = seq;
  }

  applyState(msg) {
    const editable = this.canEdit;
    this.session = msg.session;
    this.role = msg.role;
    this.you = msg.you;
    this.seq = msg.seq;
    this.metrics = msg.metrics || null;
    this.participants = msg.participants || [];
    if (msg.settings) this.settings = { ...this.settings, ...msg.settings };
    if (msg.undo) this.undo = msg.undo;
    this.quality = msg.quality || null;  // a verdict from before the resync may not apply
    this._setScene(msg.scene, msg.constraints);
    this.emit('session', msg);
    this.emit('scene', this.scene);
    this.emit('metrics', this.metrics);
    this.emit('presence', this.participants);
    this.emit('undo', this.undo);
    this._emitEditable(editable);
    this.emit('settings', this.settings);
    if (msg.geometry) this.emit('geometry', { geometry: msg.geometry, source: 'state' });
  }

  _setScene(scene, constraints) {
    if (scene) this.scene = scene;
    if (scene && scene.model && scene.model.kind) this.kind = scene.model.kind;
    const model = (scene && scene.model) || {};
    this.constraints = {
      // A quad_mesh scene writes a fixed vertex of M as its index; a target is {vertex}.
      fixed: (constraints && constraints.fixed) || (model.fixed || []).map((f) => (Number.isInteger(f) ? { vertex: f } : f)),
      handles: (constraints && constraints.handles) || model.handles || [],
    };
  }

  applyIterate(msg) {
    this._seenSeq(msg.seq);
    this.metrics = { ...(this.metrics || {}), ...(msg.metrics || {}) };
    this.lastIterate = { iteration: msg.iteration, time_ms: msg.time_ms, residuals: msg.residuals || {}, seq: msg.seq };
    this._pushResiduals(msg.residuals || {});
    this.emit('iterate', msg);
    this.emit('metrics', this.metrics);
    // Listeners of 'geometry' decode, update the buffers and render synchronously.
    if (msg.geometry) this.emit('geometry', { geometry: msg.geometry, source: 'iterate', message: msg });
    this.iterateCount++;
  }

  _pushResiduals(residuals) {
    const h = this.residualHistory;
    this.residualStep++;
    const n = h.x.length;
    for (const name of Object.keys(residuals)) {
      if (!h.terms[name]) h.terms[name] = new Array(n).fill(null);
    }
    h.x.push(this.residualStep);
    for (const [name, values] of Object.entries(h.terms)) {
      const v = residuals[name];
      values.push(typeof v === 'number' && v > 0 && Number.isFinite(v) ? v : null);
    }
    if (h.x.length > RESIDUAL_HISTORY_LIMIT) {
      const drop = h.x.length - RESIDUAL_HISTORY_LIMIT;
      h.x.splice(0, drop);
      for (const values of Object.values(h.terms)) values.splice(0, drop);
    }
  }

  applySolved(msg) {
    this._seenSeq(msg.seq);
    if (msg.metrics) this.metrics = { ...(this.metrics || {}), ...msg.metrics };
    this.lastSolved = { reason: msg.reason, iterations: msg.iterations, seq: msg.seq, quality: msg.quality || null };
    this.quality = msg.quality || null;
    if (msg.undo && Number.isInteger(msg.undo.available)) {
      // The exact history counts once the interaction has settled (drags and folds only note "≥ 1").
      this.undo = { available: msg.undo.available, redo_available: msg.undo.redo_available || 0 };
      this.emit('undo', this.undo);
    }
    this.emit('solved', msg);
    this.emit('metrics', this.metrics);
  }

  applyUpdate(msg) {
    this._seenSeq(msg.seq);
    if (msg.metrics) this.metrics = msg.metrics;
    if (msg.undo) this.undo = msg.undo;
    if (msg.quality) this.quality = msg.quality;
    if (msg.scene) this._setScene(msg.scene, msg.constraints);
    this.emit('scene', this.scene);
    this.emit('metrics', this.metrics);
    this.emit('undo', this.undo);
    if (msg.geometry) this.emit('geometry', { geometry: msg.geometry, source: 'update' });
  }

  /**
   * A drag, a fold of the slider, a solve and a group rotation (rotate_points) start an undo step
   * on the server without an `update` (structural edits, undo, redo, reset and a first fold that
   * takes the design's folds as targets send one with the exact counts): note that there is
   * something to undo.
   */
  _noteDragHistory(type) {
    if (type !== 'drag' && type !== 'fold' && type !== 'solve' && type !== 'rotate_points') return;
    if (this.undo.available > 0 && this.undo.redo_available === 0) return;
    this.undo = { available: Math.max(1, this.undo.available), redo_available: 0 };
    this.emit('undo', this.undo);
  }

  /**
   * The fold amount a `fold` applied (ours acknowledged, or a collaborator's edit) is the session's
   * now: the iterates that follow carry no `fold_amount` in their metrics (only `state`, `update`
   * and `solved` do), and without this the metrics would keep the amount from before the fold.
   */
  _noteFoldAmount(type, amount) {
    if (type !== 'fold' || typeof amount !== 'number' || !Number.isFinite(amount)) return;
    if (this.metrics && this.metrics.fold_amount === amount) return;
    this.metrics = { ...(this.metrics || {}), fold_amount: amount };
    this.emit('metrics', this.metrics);
  }

  applyEdit(msg) {
    this._seenSeq(msg.seq);
    const e = msg.edit || {};
    this._noteDragHistory(e.type);
    this._noteFoldAmount(e.type, e.amount);
    if (e.type === 'set_solver') {
      const s = { ...this.settings };
      if (e.drag_iterations !== undefined) s.drag_iterations = e.drag_iterations;
      if (e.release_iterations !== undefined) s.release_iterations = e.release_iterations;
      this.settings = s;
      this.emit('settings', this.settings);
    }
    this.emit('edit', msg);
  }

  applyPresence(msg) {
    this.participants = msg.participants || [];
    this.emit('presence', this.participants);
  }

  /** Our own command was applied (ProtocolClient matched the ack to it). */
  applyAck(msg, command) {
    this._seenSeq(msg.seq);
    if (command) {
      this._noteDragHistory(command.type);
      this._noteFoldAmount(command.type, command.amount);
    }
    if (command && command.type === 'set_solver') {
      const s = { ...this.settings };
      if (command.drag_iterations !== undefined) s.drag_iterations = command.drag_iterations;
      if (command.release_iterations !== undefined) s.release_iterations = command.release_iterations;
      this.settings = s;
      this.emit('settings', this.settings);
    }
    this.emit('ack', { message: msg, command });
  }

  /** A server error (or a local one, e.g. "not connected"), with the command that caused it. */
  applyError(msg, command) {
    this.lastError = msg;
    this.emit('error', { message: msg, command });
  }
}
