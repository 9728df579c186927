// The fold slider (composite sessions, issue 16 item 2): from the flat sheet (0 %) to the design's
// fold angles (100 %), driven by the solver. Moving the slider sends FoldCommands at most once per
// animation frame (latest wins on the server too) and a FoldEndCommand when it is let go; Play
// animates the amount up to 100 % (from 0 when it is there already), Pause stops wherever it is.
// The position follows the session (fold_amount in the metrics) unless this editor is moving it,
// or has let go and its fold_end is not yet answered: the folds sent before it are answered first,
// so from its answer on the session's amount is the one this editor last showed.

import { FoldCommand, FoldEndCommand } from '../commands/FoldCommand.js';
import { h } from './dom.js';

/** Seconds Play takes from 0 % to 100 %. */
export const FOLD_PLAY_SECONDS = 6;
/** Fold messages a second while playing. */
export const FOLD_PLAY_RATE = 15;
/**
 * Milliseconds the keys must rest before a keyboard gesture ends: a range input fires `change`
 * at every arrow or Page key, and a fold_end (a release solve) at every one of them tore the
 * sheet near the flat state. Key presses closer together than this are one gesture, as a drag is.
 */
export const FOLD_KEYS_REST_MS = 700;

/** The fold amount a session is at: its metrics while it folds, its scene, else 1 (the design). */
export function sessionFoldAmount(metrics, scene) {
  if (metrics && typeof metrics.fold_amount === 'number') return metrics.fold_amount;
  const model = scene && scene.model;
  if (model && typeof model.fold_amount === 'number') return model.fold_amount;
  return 1;
}

/** A hinge folded by at least this much is a fold the slider's first move takes as 100 % (server: kFoldCaptureMinDeg). */
export const FOLD_CAPTURE_MIN_DEG = 0.5;

/**
 * Why the slider has nothing to fold, or null when it has: a composite without fold-angle targets
 * whose creases are all flat (a blank sheet; a drawing of flat lines) — its first move would only
 * be refused ("nothing to fold"), so the slider and Play are off and this says what to do.
 * @param {object} scene  the session's scene
 * @param {number} largestFoldDeg  the largest |fold angle| of an interior edge now, degrees
 */
export function nothingToFold(scene, largestFoldDeg) {
  const model = scene && scene.model;
  if (!model || model.kind !== 'composite') return null;
  if (Array.isArray(model.fold_angles) && model.fold_angles.length) return null;
  if (largestFoldDeg >= FOLD_CAPTURE_MIN_DEG) return null;
  return model.drawing
    ? 'Nothing to fold yet: draw a mountain or valley crease on the crease board (Draw creases), or drag a corner of the sheet.'
    : 'Nothing to fold yet: every crease is flat. Drag a point to fold the design; the slider then unfolds and refolds it.';
}

/**
 * A warning when the creases lag far behind the slider (a drawing whose fold angles the sheet
 * cannot take as drawn: it stretches instead, and a crease may fold the wrong way), else null:
 * the largest error of a crease's fold angle against amount × its target (the metrics'
 * fold_angle_error_max_deg) above a quarter of amount × the largest target and 5°. An error
 * above amount × the largest target means a crease folds the wrong way or far past its angle.
 */
export function foldLagWarning(metrics, scene) {
  const model = scene && scene.model;
  const targets = model && Array.isArray(model.fold_angles) ? model.fold_angles : [];
  if (!metrics || !targets.length) return null;
  const amount = metrics.fold_amount, error = metrics.fold_angle_error_max_deg;
  if (!(typeof amount === 'number' && amount > 0) || !(typeof error === 'number' && Number.isFinite(error))) return null;
  const aim = amount * Math.max(...targets.map((t) => Math.abs(Number(t.angle) || 0)));
  if (!(error > Math.max(5, 0.25 * aim))) return null;
  const at = `${Math.round(amount * 100)} %`;
  const how = error > aim ? 'it folds the wrong way (or far past its angle)' : 'the creases lag behind the slider';
  // What to change: a drawn or imported pattern's drawing; a design made otherwise (a preset, a
  // scene file) has no drawing, so its creases and their types.
  const remedy = model.drawing
    ? 'change the drawing (fewer or gentler creases, other angles)'
    : 'change the creases (their types — a smooth crease does not fold — or their angles)';
  return `⚠ A crease is ${Math.round(error)}° from its target at ${at}: ${how}. The sheet cannot take these fold angles as they are and stretches instead; ${remedy}.`;
}

export class FoldPanel {
  /**
   * @param {{state, send, errorSlots, largestFoldDeg?: () => number}} options  largestFoldDeg: the
   *        largest |fold angle| of an interior edge of the drawn geometry, degrees
   */
  constructor(parent, { state, send, errorSlots, largestFoldDeg = () => 0 }) {
    this.state = state;
    this.send = send;
    this.largestFoldDeg = largestFoldDeg;
    this.moving = false;   // this editor is moving the slider (by hand or playing)
    this.letGo = null;     // the FoldEndCommand of this editor's last gesture, until it is answered
    this.playing = false;
    this.pending = null;   // amount to send at the next frame
    this.playUnsent = null;  // amount Play has shown and not sent yet
    this.raf = 0;
    this.slider = h('input', { type: 'range', min: '0', max: '100', step: '1', value: '100', class: 'fold-slider',
      testid: 'fold-slider', 'aria-label': 'Fold amount (%)' });
    this.label = h('span', { class: 'num fold-amount', testid: 'fold-amount' }, '100 %');
    this.playButton = h('button', { class: 'btn small', testid: 'fold-play', onclick: () => this.togglePlay() }, 'Play');
    this.slider.addEventListener('input', () => {
      if (this.playing) this.pause(false);
      this.moving = true;
      this._queue(Number(this.slider.value) / 100);
    });
    // A pointer gesture ends at its `change`; a key press's `change` only once the keys rest.
    this.keyGesture = false;
    this.keysRest = 0;
    this.slider.addEventListener('pointerdown', () => { this.keyGesture = false; });
    this.slider.addEventListener('keydown', () => { this.keyGesture = true; });
    this.slider.addEventListener('change', () => {
      this._stopKeysRest();
      if (!this.keyGesture) {
        this._end();
        return;
      }
      this.keysRest = setTimeout(() => {
        this.keysRest = 0;
        this._end();
      }, FOLD_KEYS_REST_MS);
    });
    // Points whose creases cannot all fold (geometry.fold_conflicts): the slider cannot reach them.
    this.conflicts = h('div', { class: 'fold-conflicts', testid: 'fold-conflicts', role: 'status', hidden: true });
    this.conflictsKey = '';
    // How far the creases are from their targets once the slider is let go (foldLagWarning).
    this.lag = h('div', { class: 'fold-conflicts', testid: 'fold-lag', role: 'status', hidden: true });
    this.root = h('section', { class: 'panel', testid: 'fold-panel', hidden: true },
      h('h3', {}, 'Fold'),
      h('div', { class: 'row' }, this.slider, this.label, this.playButton),
      errorSlots.slot('fold:amount'),
      this.nothing = h('p', { class: 'muted small', testid: 'fold-nothing', hidden: true }),
      this.conflicts,
      this.lag,
      h('p', { class: 'muted small' }, '0 %: the flat sheet · 100 %: the design\'s fold angles. The solver keeps every state developable; the first move takes the current folds as 100 %.'));
    parent.appendChild(this.root);
    // A fresh state (a re-join) is the session's own: a let-go sent before it is not waited for.
    state.on('session', () => { this.letGo = null; });
    for (const ev of ['scene', 'session', 'metrics', 'editable']) state.on(ev, () => this.render());
    const answered = ({ command }) => {
      if (!command || command !== this.letGo) return;
      this.letGo = null;
      this.render();
    };
    state.on('ack', answered);
    state.on('error', answered);
    state.on('geometry', ({ geometry }) => {
      this.showConflicts(geometry && geometry.kind === 'composite' ? geometry.fold_conflicts : null);
      // A drag may fold a flat design: the slider then has something to fold.
      if (!this.moving && !this.letGo) queueMicrotask(() => this.render());
    });
    // The connection dropped (or the link is view only now): a gesture in progress is over — Play
    // stops, nothing more is sent, and the resync shows where the session stands.
    state.on('editable', (editable) => { if (!editable) this._interrupt(); });
    this.render();
  }

  _interrupt() {
    if (this.raf) cancelAnimationFrame(this.raf);
    this.raf = 0;
    this.pending = null;
    this._stopKeysRest();
    this.playing = false;
    if (this.playRaf) cancelAnimationFrame(this.playRaf);
    this.playRaf = 0;
    this.playUnsent = null;
    this.moving = false;
    this.letGo = null;
    this.render();
  }

  /** Lists the points that cannot fold ([{vertex, reason, position, flat?}]; none: hidden). */
  showConflicts(conflicts) {
    const list = Array.isArray(conflicts) ? conflicts : [];
    const key = list.map((c) => `${c.vertex}:${c.reason}`).join('|');
    if (key === this.conflictsKey) return;
    this.conflictsKey = key;
    this.conflicts.hidden = !list.length;
    if (!list.length) {
      this.conflicts.replaceChildren();
      return;
    }
    const at = (c) => (Array.isArray(c.flat) ? `At (${c.flat.map((x) => +x.toPrecision(4)).join(', ')}) on the sheet: ` : '');
    this.conflicts.replaceChildren(
      h('strong', {}, `⚠ ${list.length === 1 ? 'One point' : `${list.length} points`} cannot fold as drawn`),
      h('ul', {}, list.map((c) => h('li', {}, at(c) + c.reason))),
      h('p', { class: 'muted small' }, 'The slider stops short there and the sheet would stretch. The crease board marks them.'));
  }

  render() {
    const st = this.state;
    this.root.hidden = st.kind !== 'composite';
    const editable = st.canEdit;
    const nothing = this.moving || this.playing ? null : nothingToFold(st.scene, this.largestFoldDeg());
    this.slider.disabled = !editable || !!nothing;
    this.playButton.disabled = !editable || !!nothing;
    this.nothing.hidden = !nothing || !editable;
    this.nothing.textContent = nothing || '';
    this.playButton.textContent = this.playing ? 'Pause' : 'Play';
    if (this.moving || this.letGo) return;
    const lag = foldLagWarning(st.metrics, st.scene);
    this.lag.hidden = !lag;
    this.lag.textContent = lag || '';
    const amount = sessionFoldAmount(st.metrics, st.scene);
    this.slider.value = String(Math.round(amount * 100));
    this._showAmount(amount);
  }

  _showAmount(amount) {
    this.label.textContent = `${Math.round(amount * 100)} %`;
  }

  _queue(amount) {
    this.pending = Math.min(1, Math.max(0, amount));
    this._showAmount(this.pending);
    if (!this.raf) this.raf = requestAnimationFrame(() => this._flush());
  }

  _flush() {
    this.raf = 0;
    if (this.pending === null) return;
    const amount = this.pending;
    this.pending = null;
    this.send(new FoldCommand(amount, { source: 'fold:amount' }));
  }

  _stopKeysRest() {
    if (this.keysRest) clearTimeout(this.keysRest);
    this.keysRest = 0;
  }

  /** The gesture ends: what is still pending, then fold_end. */
  _end() {
    this._stopKeysRest();
    if (!this.moving) return;
    if (this.raf) cancelAnimationFrame(this.raf);
    this.raf = 0;
    this._flush();
    const letGo = new FoldEndCommand({ source: 'fold:amount' });
    this.letGo = letGo;
    this.send(letGo);
    this.moving = false;
    this.endedAt = Date.now();
  }

  /** This editor is folding, or stopped less than 5 s ago (the release is still settling). */
  recentlyFolding() {
    return this.moving || this.playing || (this.endedAt !== undefined && Date.now() - this.endedAt < 5000);
  }

  togglePlay() {
    if (this.playing) this.pause(true);
    else this.play();
  }

  play() {
    this._stopKeysRest();  // a keyboard gesture goes on as Play; Play's end is its end
    let amount = Number(this.slider.value) / 100;
    if (amount >= 1) amount = 0;
    this.playing = true;
    this.moving = true;
    this.render();
    let last = performance.now();
    let lastSent = last;
    const step = (now) => {
      if (!this.playing) return;
      amount = Math.min(1, amount + (now - last) / 1000 / FOLD_PLAY_SECONDS);
      last = now;
      this.slider.value = String(Math.round(amount * 100));
      this._showAmount(amount);
      this.playUnsent = amount;
      // At most FOLD_PLAY_RATE messages a second (the server coalesces, but every message it
      // takes streams geometry back), and always the last one.
      if (amount >= 1 || now - lastSent >= 1000 / FOLD_PLAY_RATE) {
        this._sendPlayed();
        lastSent = now;
      }
      if (amount >= 1) {
        this.pause(true);
        return;
      }
      this.playRaf = requestAnimationFrame(step);
    };
    this.playUnsent = amount;
    this._sendPlayed();
    this.playRaf = requestAnimationFrame(step);
  }

  /** Sends the amount Play shows when it has not been sent yet. */
  _sendPlayed() {
    if (this.playUnsent === null) return;
    const amount = this.playUnsent;
    this.playUnsent = null;
    this.send(new FoldCommand(amount, { source: 'fold:amount' }));
  }

  /**
   * Stops playing; `settle` ends the gesture (fold_end) where the slider shows it: the amount
   * shown since the last message goes first, so the session stops where Pause was pressed.
   */
  pause(settle) {
    this.playing = false;
    if (this.playRaf) cancelAnimationFrame(this.playRaf);
    this.playRaf = 0;
    if (settle) {
      this._sendPlayed();
      this._end();
    }
    this.playUnsent = null;
    this.render();
  }
}
