// Toasts: one error toast (data-testid="error-message", the latest server error with its text)
// and one info toast for local hints.

import { h } from './dom.js';

export function describeError(msg) {
  if (!msg) return '';
  const text = msg.message || msg.code || 'error';
  // The daemon's messages usually name the path already.
  const path = msg.path && msg.path !== 'type' && !text.includes(msg.path) ? ` (${msg.path})` : '';
  return `${text}${path}`;
}

/** A toast's title in words for an error code of the protocol (docs/protocol.md, "Errors"). */
const CODE_TITLES = {
  invalid: 'Not accepted',
  invalid_json: 'Not readable',
  limit: 'Too large',
  conflict: 'Not possible now',
  diverged: 'The solver gave up',
  forbidden: 'View only',
  unauthorized: 'Not allowed',
  time_budget: 'Took too long',
  quarantined: 'Session unavailable',
  unavailable: 'Session unavailable',
  store_unavailable: 'Storage unavailable',
  session_full: 'Session full',
  rate_limited: 'Too many messages',
  queue_full: 'Server busy',
  not_ready: 'Not ready yet',
  not_joined: 'Not connected',
  unprocessable: 'Cannot export this state',
  too_large: 'Too large',
  too_deep: 'Not readable',
  session_moved: 'Session moved',
  solve_failed: 'The solve failed',
  offline: 'Offline',
  internal: 'Server error',
};

/** The title of an error toast: the code in words (an unknown code as it is). */
export function errorTitle(code) {
  if (!code) return 'Error';
  return CODE_TITLES[code] || code;
}

export class Toasts {
  constructor(parent) {
    this.errorText = h('span', { class: 'toast-text' });
    this.errorTitle = h('strong', { class: 'toast-title' });
    // The test id is on the text only (not the close button).
    this.error = h('div', { class: 'toast toast-error', role: 'alert', hidden: true },
      h('div', { testid: 'error-message' }, this.errorTitle, ' ', this.errorText),
      h('button', { class: 'toast-close', 'aria-label': 'Dismiss', title: 'Dismiss', onclick: () => this.hideError() }, '×'));
    this.info = h('div', { class: 'toast toast-info', role: 'status', hidden: true });
    this.root = h('div', { class: 'toasts' }, this.info, this.error);
    parent.appendChild(this.root);
    this._errorTimer = 0;
    this._infoTimer = 0;
  }

  /** Shows a server (or connection) error; `context` names the action that caused it. */
  showError(msg, context) {
    this.errorTitle.textContent = `${context ? `${context}: ` : ''}${errorTitle(msg.code)}`;
    this.errorTitle.title = msg.code ? `error code: ${msg.code}` : '';
    this.errorText.textContent = describeError(msg);
    this.error.hidden = false;
    clearTimeout(this._errorTimer);
    this._errorTimer = setTimeout(() => this.hideError(), 10000);
  }

  hideError() {
    this.error.hidden = true;
  }

  showInfo(text, ms = 3000) {
    this.info.textContent = text;
    this.info.hidden = false;
    clearTimeout(this._infoTimer);
    this._infoTimer = setTimeout(() => { this.info.hidden = true; }, ms);
  }
}

/** Error slots next to controls: a command's `source` names the slot its error shows in. */
export class ErrorSlots {
  constructor() {
    this.slots = new Map();
    this.timers = new Map();
  }

  /** Creates (or reuses) the slot element for `source`. */
  slot(source) {
    let el = this.slots.get(source);
    if (!el) {
      el = h('div', { class: 'field-error', role: 'alert', hidden: true, dataset: { source } });
      this.slots.set(source, el);
    }
    return el;
  }

  /** Shows `text` in the slot of `source` (or of its prefix, e.g. "solver" for "solver:x"). */
  show(source, text) {
    let el = this.slots.get(source);
    if (!el && source && source.includes(':')) el = this.slots.get(source.split(':')[0]);
    if (!el) return false;
    // One message once: another slot showing the same text (a view-only page's refusals of F, H
    // and R each named their own control) makes way for this one.
    for (const other of this.slots.values())
      if (other !== el && !other.hidden && other.textContent === text) {
        other.hidden = true;
        clearTimeout(this.timers.get(other));
      }
    el.textContent = text;
    el.hidden = false;
    clearTimeout(this.timers.get(el));
    this.timers.set(el, setTimeout(() => { el.hidden = true; }, 8000));
    return true;
  }

  /** Whether the slot of `source` (or of its prefix) shows its text on screen now. */
  isShown(source) {
    let el = this.slots.get(source);
    if (!el && source && source.includes(':')) el = this.slots.get(source.split(':')[0]);
    return !!el && !el.hidden && el.isConnected && el.getClientRects().length > 0;
  }

  clear(source) {
    const el = this.slots.get(source);
    if (!el) return;
    el.hidden = true;
    el.textContent = '';  // nothing stale left to read (a screen reader, a test reading the text)
    clearTimeout(this.timers.get(el));
  }
}
