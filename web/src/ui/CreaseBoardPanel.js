// The crease-pattern drawing board (composite sessions whose scene carries a drawing, issue 16
// item 3). A sidebar panel "Crease pattern" opens it with "Draw creases"; the board then covers
// the 3D view and the bottom panels (a large drawing area; the sidebar, the Fold slider among it,
// stays). Tools:
//   Select  click a stroke to select it: its assignment (M V F C), fold angle, Delete; its points
//           as handles: drag one to move it, double-click the stroke to add a point, Alt-click a
//           point (or "Remove point") to delete it. The outline is not editable.
//   Line    click two points: a straight crease.
//   Curve   click points (a preview follows the pointer); double-click or Enter finishes,
//           Backspace removes the last point, Escape cancels.
// Points snap to stroke vertices, then onto strokes, within 10 px (a marker shows it); points
// off the sheet are refused. Every edit is a command (draw_crease, erase_crease, relabel_crease,
// reshape_crease) the server answers with an `update` of the scene, or an error (toast).

import { formatFixed, h } from './dom.js';
import { CreaseBoard } from '../view/CreaseBoard.js';
import {
  ASSIGNMENT_NAMES, DRAW_ASSIGNMENTS, DrawCreaseCommand, EraseCreaseCommand, RelabelCreaseCommand, ReshapeCreaseCommand,
  STROKE_POINTS_MAX,
} from '../commands/index.js';
import {
  DEFAULT_FOLD_ANGLE, SNAP_PX, STROKE_STYLES, dist, drawingStrokes, foldAngleMagnitude, hitPoint, hitStroke, insertionIndex,
  insideSheet, nearestOnPolyline, reshapedCurved, roundPoint, snapPoint,
} from '../geometry/creaseDrawing.js';

const TOOLS = [
  ['select', 'Select', 'Select a crease: relabel it, move, add (double-click) or remove (Alt-click) its points, Delete erases it'],
  ['line', 'Line', 'A straight crease: click its two ends, on the outline or on creases'],
  ['curve', 'Curve', 'A curved crease: click points along it; double-click or Enter finishes, Backspace removes the last point, Esc cancels'],
];
const HINTS = {
  select: 'Click a crease to select it · drag its points · double-click it to add a point · Alt-click a point to remove it · Delete erases it',
  line: 'Click the two ends of a straight crease, on the outline or on another crease (points snap within 10 px)',
  curve: 'Click points along the curve, its ends on the outline or a crease · double-click or Enter finishes · Backspace: undo a point · Esc cancels',
};
/** Pick distance for strokes and handles (px). */
const PICK_PX = 8;
/** A press this close to the last placed point is a double-click's second press, not a point (px). */
const SAME_POINT_PX = 3;

/**
 * Which toolbar controls are off: a view-only editor changes nothing (not even the defaults of new
 * creases, which it cannot draw), the outline has no assignment, and only mountain and valley
 * creases have a fold angle.
 * @param {{editable: boolean, crease: boolean, outline: boolean, assignment: string}} shown
 *   crease/outline: what is selected; assignment: the selected crease's or the new creases'
 */
export function boardControlStates({ editable, crease, outline, assignment }) {
  const folds = assignment === 'M' || assignment === 'V';
  return {
    assignmentDisabled: outline || !editable,
    angleDisabled: outline || !folds || !editable,
    editsDisabled: !editable || !crease,
  };
}

export class CreaseBoardPanel {
  /**
   * @param {object} deps {host (element the board covers, positioned), sidebar, state, send, errorSlots}
   */
  constructor({ host, sidebar, state, send, errorSlots }) {
    this.state = state;
    this.send = send;
    this.tool = 'select';
    this.selected = null;
    this.selectedPoint = null;
    this.draft = [];
    this.pointer = null;   // last pointer position (sheet), snapped while placing
    this.snap = null;
    this.drag = null;      // {index, point, points, start, moved}
    this.pending = [];     // draws sent, not yet applied
    this.edit = null;      // a reshape sent, shown until the scene comes
    this.relabelSent = null;  // {index, assignment, angle} of a relabel sent, until the scene comes
    this.defaults = { assignment: 'V', angle: DEFAULT_FOLD_ANGLE };
    this.strokes = [];

    // Sidebar: what the board is, and the button that opens it.
    this.openButton = h('button', { class: 'btn primary', testid: 'draw-creases', onclick: () => this.toggle() }, 'Draw creases');
    this.summary = h('p', { class: 'muted small', testid: 'crease-pattern-summary' });
    this.panel = h('section', { class: 'panel', testid: 'crease-pattern-panel', hidden: true },
      h('h3', {}, 'Crease pattern'), h('div', { class: 'button-row' }, this.openButton), this.summary);
    sidebar.appendChild(this.panel);

    // The board: toolbar, drawing area, status line.
    this.toolButtons = Object.fromEntries(TOOLS.map(([id, label, title]) => [id,
      h('button', { class: 'btn small', testid: `crease-tool-${id}`, title, 'aria-pressed': 'false', onclick: () => this.setTool(id) }, label)]));
    this.assignButtons = Object.fromEntries(DRAW_ASSIGNMENTS.map((a) => [a,
      h('button', { class: 'btn small assign-btn', testid: `crease-assignment-${a}`, title: ASSIGNMENT_NAMES[a], 'aria-pressed': 'false', onclick: () => this.chooseAssignment(a) },
        h('span', { class: 'assign-swatch', style: { background: STROKE_STYLES[a].color } }), a)]));
    this.angleInput = h('input', { type: 'number', class: 'input small crease-angle', min: '1', max: '180', step: 'any', value: String(DEFAULT_FOLD_ANGLE),
      testid: 'crease-angle', 'aria-label': 'Fold angle (degrees)', title: 'Fold angle in degrees (mountain and valley creases)' });
    // 'change' comes on Enter and when the field loses focus with a new value: one edit per value.
    this.angleInput.addEventListener('change', () => this.chooseAngle());
    this.targetLabel = h('span', { class: 'small crease-target', testid: 'crease-target' });
    this.deleteButton = h('button', { class: 'btn small', testid: 'crease-delete', title: 'Erase the selected crease (Delete)', onclick: () => this.eraseSelected() }, 'Delete');
    this.removePointButton = h('button', { class: 'btn small', testid: 'crease-remove-point', title: 'Remove the selected point of the crease (Alt-click a point)', onclick: () => this.removePoint(this.selectedPoint) }, 'Remove point');
    this.closeButton = h('button', { class: 'btn small', testid: 'crease-board-close', title: 'Back to the 3D view (Esc)', onclick: () => this.close() }, 'Done');
    this.hint = h('span', { class: 'crease-hint', testid: 'crease-board-hint' });
    this.coords = h('span', { class: 'num crease-coords' });
    this.area = h('div', { class: 'crease-board-area' }, h('div', { class: 'crease-board-errors' }, errorSlots.slot('crease-board')));
    this.overlay = h('div', { class: 'crease-board-overlay', testid: 'crease-board-panel', hidden: true, dataset: { tool: this.tool } },
      h('div', { class: 'crease-board-toolbar' },
        h('div', { class: 'tool-group', role: 'group', 'aria-label': 'Tool' }, Object.values(this.toolButtons)),
        this.targetLabel,
        h('div', { class: 'tool-group', role: 'group', 'aria-label': 'Assignment' }, Object.values(this.assignButtons)),
        h('label', { class: 'small crease-angle-label' }, this.angleInput, '°'),
        this.deleteButton, this.removePointButton,
        h('span', { class: 'crease-toolbar-spacer' }),
        this.closeButton),
      this.area,
      h('div', { class: 'crease-board-status' }, this.hint, this.coords));
    host.appendChild(this.overlay);
    this.board = new CreaseBoard(this.area);

    const svg = this.board.svg;
    svg.addEventListener('pointerdown', (e) => this._pointerDown(e));
    svg.addEventListener('pointermove', (e) => this._pointerMove(e));
    svg.addEventListener('pointerup', (e) => this._pointerUp(e));
    svg.addEventListener('pointercancel', () => this._cancelDrag());
    svg.addEventListener('pointerleave', () => { if (!this.drag) { this.pointer = null; this.snap = null; this._renderOverlay(); } });
    svg.addEventListener('dblclick', (e) => this._doubleClick(e));

    for (const ev of ['scene', 'session']) state.on(ev, () => this._sceneChanged());
    // Points whose creases cannot all fold (geometry.fold_conflicts), marked on the sheet.
    this.conflicts = [];
    state.on('geometry', ({ geometry }) => {
      const list = geometry && geometry.kind === 'composite' && Array.isArray(geometry.fold_conflicts) ? geometry.fold_conflicts : [];
      const marked = list.filter((c) => Array.isArray(c.flat)).map((c) => ({ point: c.flat, reason: c.reason }));
      if (JSON.stringify(marked) === JSON.stringify(this.conflicts)) return;
      this.conflicts = marked;
      this._renderOverlay();
    });
    state.on('error', ({ command, message }) => this._commandFailed(command, message));
    // The role arrives with the session, the connection after it: the hint follows both.
    for (const ev of ['editable', 'session']) {
      state.on(ev, () => {
        this._renderToolbar();
        if (!this.hint.classList.contains('warn')) this._setHint(this._toolHint());
      });
    }
    this._sceneChanged();
    this.setTool('select');
  }

  get isOpen() {
    return !this.overlay.hidden;
  }

  get editable() {
    return this.state.canEdit;
  }

  open() {
    if (this.panel.hidden) return;
    this.overlay.hidden = false;
    this.openButton.textContent = 'Back to 3D';
    this.board.resize();
  }

  close() {
    this.overlay.hidden = true;
    this.openButton.textContent = 'Draw creases';
    this._cancelDraft();
  }

  toggle() {
    if (this.isOpen) this.close();
    else this.open();
  }

  /** Client (page) coordinates of a sheet point on the board, for tests (null when closed). */
  clientPoint(p) {
    const q = this.board.toScreen(p);
    if (!q || !this.isOpen) return null;
    const r = this.board.svg.getBoundingClientRect();
    return { x: r.left + q[0], y: r.top + q[1] };
  }

  // ---- state ----------------------------------------------------------------------------------

  _sceneChanged() {
    const st = this.state;
    const strokes = st.kind === 'composite' ? drawingStrokes(st.scene) : null;
    this.panel.hidden = !strokes;
    if (!strokes) {
      if (this.isOpen) this.close();
      return;
    }
    // A collaborator's edit renumbered the strokes under a drag: it ends (nothing sent).
    if (this.drag && strokes.length !== this.strokes.length) this.drag = null;
    this.strokes = strokes;
    this.pending = [];
    this.edit = null;
    this.relabelSent = null;
    if (this.selected !== null && !strokes[this.selected]) this._select(null);
    const creases = strokes.filter((s) => s.assignment !== 'B').length;
    const units = (st.scene && st.scene.units) || 'mm';  // absent = mm (scene schema)
    this.board.setStrokes(strokes);
    const nb = this.board.bounds;
    this.summary.textContent = `${creases} crease${creases === 1 ? '' : 's'} drawn${nb ? ` on a ${+(nb.x1 - nb.x0).toPrecision(4)} × ${+(nb.y1 - nb.y0).toPrecision(4)} ${units} sheet` : ''}. Draw lines and curves on the flat sheet; every edit rebuilds it flat.`;
    this.units = units;
    this._renderToolbar();
    this._render();
  }

  _commandFailed(command, message) {
    if (!command || !String(command.source || '').startsWith('crease-board')) return;
    // A crease the server refused is drawn again as a draft, its points kept (a tryout's curve
    // with a loose end vanished whole): finish it on the outline or a crease, or Esc drops it.
    // Not when the connection failed: its outcome is unknown, and the resync shows it if drawn.
    const local = !!message && ['offline', 'disconnected', 'closed'].includes(message.code);
    const refused = local ? null : this.pending.find((p) => p.command === command);
    if (refused && refused.curved && this.draft.length === 0 && this.tool === 'curve') {
      this.draft = refused.points.slice();
      this._setHint('Not drawn — its points are kept: click a point on the outline or on a crease and press Enter; Backspace removes the last point, Esc drops it.', true);
      this._renderOverlay();
    }
    this.pending = [];
    this.edit = null;
    this.relabelSent = null;
    this._render();
  }

  setTool(tool) {
    if (!TOOLS.some(([id]) => id === tool)) return;
    if ((tool === 'line' || tool === 'curve') && !this.editable) return;
    this.tool = tool;
    this._cancelDraft();
    if (tool !== 'select') this._select(null);
    this.overlay.dataset.tool = tool;
    this._setHint(this._toolHint());
    this._renderToolbar();
    this._render();
  }

  _select(index) {
    if (index !== this.selected) this.selectedAt = performance.now();
    this.selected = index;
    this.selectedPoint = null;
    this._renderToolbar();
  }

  /** The selected stroke when it is a crease (not the outline), else null. */
  _selectedCrease() {
    const s = this.selected !== null ? this.strokes[this.selected] : null;
    return s && s.assignment !== 'B' ? s : null;
  }

  /** The hint of the current tool; a view-only or offline page is told why it cannot draw. */
  _toolHint() {
    if (this.editable) return HINTS[this.tool];
    return this.state.role === 'view'
      ? 'Click a crease to see its kind and angle · this link is view only: ask for the edit link to draw'
      : 'Not connected: drawing resumes once the page has reconnected';
  }

  _setHint(text, warn = false) {
    this.hint.textContent = text;
    this.hint.title = text;
    this.hint.classList.toggle('warn', warn);
  }

  // ---- toolbar --------------------------------------------------------------------------------

  _renderToolbar() {
    const editable = this.editable;
    for (const [id, b] of Object.entries(this.toolButtons)) {
      b.setAttribute('aria-pressed', String(id === this.tool));
      b.disabled = id !== 'select' && !editable;
    }
    const stroke = this.selected !== null ? this.strokes[this.selected] : null;
    const crease = this._selectedCrease();
    const outline = stroke && !crease;
    const assignment = crease ? crease.assignment : this.defaults.assignment;
    const angle = crease ? foldAngleMagnitude(crease) : this.defaults.angle;
    if (outline) {
      this.targetLabel.textContent = 'The sheet’s outline — not editable: draw creases from edge to edge';
    } else if (crease) {
      const n = crease.points.length;
      this.targetLabel.textContent = `Crease ${this.selected} · ${crease.curved ? 'curved' : 'straight'}, ${n} points:`;
    } else {
      this.targetLabel.textContent = 'New creases:';
    }
    const controls = boardControlStates({ editable, crease: !!crease, outline: !!outline, assignment });
    for (const [a, b] of Object.entries(this.assignButtons)) {
      b.setAttribute('aria-pressed', String(!outline && a === assignment));
      b.disabled = controls.assignmentDisabled;
    }
    if (document.activeElement !== this.angleInput || this._shownFor !== this.selected) {
      this.angleInput.value = angle !== undefined ? String(+angle.toFixed(3)) : '';
    }
    this._shownFor = this.selected;
    this.angleInput.disabled = controls.angleDisabled;
    this.deleteButton.hidden = !crease;
    this.deleteButton.disabled = controls.editsDisabled;
    this.removePointButton.hidden = !crease || this.selectedPoint === null;
    this.removePointButton.disabled = controls.editsDisabled;
  }

  chooseAssignment(a) {
    const crease = this._selectedCrease();
    if (!crease) {
      this.defaults.assignment = a;
      this._renderToolbar();
      this._render();
      return;
    }
    if (!this.editable || crease.assignment === a) return;
    const angle = a === 'M' || a === 'V' ? foldAngleMagnitude(crease) || this.defaults.angle : undefined;
    this._sendRelabel(a, angle);
  }

  chooseAngle() {
    const angle = Number(this.angleInput.value);
    if (!(angle > 0 && angle <= 180)) {
      this._setHint('Fold angle: enter degrees, more than 0 and at most 180', true);
      return;
    }
    const crease = this._selectedCrease();
    if (!crease) {
      this.defaults.angle = angle;
      return;
    }
    if (!this.editable || (crease.assignment !== 'M' && crease.assignment !== 'V') || angle === foldAngleMagnitude(crease)) return;
    this._sendRelabel(crease.assignment, angle);
  }

  /**
   * Relabels the selected crease, unless the same relabel is already on its way: the scene that
   * answers it has not come yet, so the crease still shows its old label or angle (Enter and the
   * field's change, a second click on M), and a second one would be a second undo step.
   */
  _sendRelabel(assignment, angle) {
    const index = this.selected;
    const sent = this.relabelSent;
    if (sent && sent.index === index && sent.assignment === assignment && sent.angle === angle) return;
    const command = this._sendSafely(() => new RelabelCreaseCommand(index, assignment, angle, { source: 'crease-board:relabel' }));
    if (command) this.relabelSent = { index, assignment, angle };
  }

  eraseSelected() {
    if (!this._selectedCrease() || !this.editable) return;
    const index = this.selected;
    this._select(null);
    this._sendSafely(() => new EraseCreaseCommand(index, { source: 'crease-board:erase' }));
    this._render();
  }

  /** Builds a command (its checks may refuse the arguments: said in the hint) and sends it. */
  _sendSafely(build) {
    let command;
    try {
      command = build();
    } catch (e) {
      this._setHint(e.message, true);
      return null;
    }
    this.send(command);
    return command;
  }

  // ---- pointer --------------------------------------------------------------------------------

  _sheetPoint(e) {
    const r = this.board.svg.getBoundingClientRect();
    return this.board.toSheet([e.clientX - r.left, e.clientY - r.top]);
  }

  _px(n) {
    return n * this.board.unitsPerPx;
  }

  /** p snapped (exactly onto a stroke) or else rounded to a tenth of a px. */
  _snap(p, exclude = -1) {
    const s = snapPoint(p, this.board.geometry, this._px(SNAP_PX), { exclude });
    if (!s.kind) s.point = roundPoint(s.point, this._px(0.1));
    return s;
  }

  _onSheet(p) {
    return insideSheet(p, this.board.loops, this._px(1));
  }

  _pointerDown(e) {
    if (e.button !== 0) return;
    const p = this._sheetPoint(e);
    if (!p) return;
    e.preventDefault();
    if (this.tool === 'select') {
      this._selectDown(e, p);
      return;
    }
    if (!this.editable) return;
    const snap = this._snap(p);
    const q = snap.point;
    if (this.draft.length && dist(q, this.draft[this.draft.length - 1]) <= this._px(SAME_POINT_PX)) return;
    if (!this._onSheet(q)) {
      this._setHint('That point is off the sheet: creases are drawn on the sheet.', true);
      return;
    }
    if (this.draft.length >= STROKE_POINTS_MAX) {
      this._setHint(`A crease has at most ${STROKE_POINTS_MAX} points.`, true);
      return;
    }
    this.draft.push(q);
    this._setHint(this._toolHint());
    if (this.tool === 'line' && this.draft.length === 2) this.finishDraft();
    else this._renderOverlay();
  }

  _selectDown(e, p) {
    const crease = this._selectedCrease();
    if (crease) {
      const k = hitPoint(p, crease.points, this._px(PICK_PX));
      if (k >= 0) {
        this.selectedPoint = k;
        this._renderToolbar();
        if (e.altKey) {
          this.removePoint(k);
          return;
        }
        if (this.editable) {
          this.drag = { index: this.selected, point: k, points: crease.points.map((q) => q.slice()), start: [e.clientX, e.clientY], moved: false };
          this.board.svg.setPointerCapture(e.pointerId);
        }
        this._render();
        return;
      }
    }
    const hit = hitStroke(p, this.board.geometry, this._px(PICK_PX));
    this._select(hit >= 0 ? hit : null);
    this._render();
  }

  _pointerMove(e) {
    const p = this._sheetPoint(e);
    if (!p) return;
    this.coords.textContent = `x ${formatFixed(p[0], 1)}  y ${formatFixed(p[1], 1)} ${this.units || ''}`;
    if (this.drag) {
      const d = this.drag;
      if (!d.moved && Math.hypot(e.clientX - d.start[0], e.clientY - d.start[1]) < 3) return;
      d.moved = true;
      const stroke = this.strokes[d.index];
      const end = !stroke.closed && (d.point === 0 || d.point === d.points.length - 1);
      const snap = end ? this._snap(p, d.index) : { point: roundPoint(p, this._px(0.1)), kind: null };
      this.snap = snap;
      if (this._onSheet(snap.point)) d.points[d.point] = snap.point;
      this.board.view.edit = { index: d.index, points: d.points };
      this._render();
      return;
    }
    if (this.tool === 'select') return;
    this.snap = this._snap(p);
    this.pointer = this.snap.point;
    this._renderOverlay();
  }

  _pointerUp(e) {
    const d = this.drag;
    if (!d) return;
    this.drag = null;
    this.snap = null;
    if (this.board.svg.hasPointerCapture(e.pointerId)) this.board.svg.releasePointerCapture(e.pointerId);
    if (!d.moved) {
      this._render();
      return;
    }
    const stroke = this.strokes[d.index];
    const command = this._sendSafely(() => new ReshapeCreaseCommand(d.index, d.points, reshapedCurved(stroke, d.points.length), { source: 'crease-board:reshape' }));
    this.edit = command ? { index: d.index, points: d.points } : null;
    this._render();
  }

  _cancelDrag() {
    this.drag = null;
    this.snap = null;
    this._render();
  }

  _doubleClick(e) {
    e.preventDefault();
    if (this.tool === 'curve') {
      this.finishDraft();
      return;
    }
    if (this.tool !== 'select' || !this.editable) return;
    const crease = this._selectedCrease();
    const p = this._sheetPoint(e);
    // A double-click on a crease not selected before selects it only.
    if (!crease || !p || performance.now() - (this.selectedAt || 0) < 700) return;
    if (hitPoint(p, crease.points, this._px(PICK_PX)) >= 0) return;
    const g = this.board.geometry[this.selected];
    if (hitStroke(p, [g], this._px(PICK_PX)) < 0) return;
    if (crease.points.length >= STROKE_POINTS_MAX) {
      this._setHint(`A crease has at most ${STROKE_POINTS_MAX} points.`, true);
      return;
    }
    const k = insertionIndex(g, p);
    const points = crease.points.map((q) => q.slice());
    points.splice(k, 0, roundPoint(nearestOnPolyline(p, g.polyline).point, this._px(0.1)));
    const index = this.selected;
    const command = this._sendSafely(() => new ReshapeCreaseCommand(index, points, reshapedCurved(crease, points.length), { source: 'crease-board:reshape' }));
    if (command) {
      this.edit = { index, points };
      this.selectedPoint = k;
      this._renderToolbar();
      this._render();
    }
  }

  /** Deletes point k of the selected crease (its ends stay: they hold it to the outline or a crease). */
  removePoint(k) {
    const crease = this._selectedCrease();
    if (!crease || k === null || k === undefined || !this.editable) return;
    const n = crease.points.length;
    if (!crease.closed && (k === 0 || k === n - 1)) {
      this._setHint('The ends of a crease stay on the outline or on a crease: drag them instead, or delete the crease.', true);
      return;
    }
    if (n - 1 < (crease.closed ? 3 : 2)) {
      this._setHint('A crease needs at least two points: delete the crease instead.', true);
      return;
    }
    const points = crease.points.filter((_, i) => i !== k).map((q) => q.slice());
    const index = this.selected;
    const command = this._sendSafely(() => new ReshapeCreaseCommand(index, points, reshapedCurved(crease, points.length), { source: 'crease-board:reshape' }));
    if (command) {
      this.edit = { index, points };
      this.selectedPoint = null;
      this._renderToolbar();
      this._render();
    }
  }

  // ---- drafts ---------------------------------------------------------------------------------

  /** Sends the crease being drawn (Line: 2 points; Curve: ≥ 3). */
  finishDraft() {
    // Offline: the draft waits (its points kept) until the page has reconnected.
    if (!this.editable) {
      this._setHint(this._toolHint(), true);
      return;
    }
    const curved = this.tool === 'curve';
    const points = this.draft;
    if (curved && points.length < 3) {
      if (points.length) this._setHint('A curve needs at least 3 points (or draw a straight crease with the Line tool).', true);
      return;
    }
    if (!curved && points.length !== 2) return;
    const { assignment, angle } = this.defaults;
    const command = this._sendSafely(() => new DrawCreaseCommand(points, { curved, assignment, foldAngle: angle }, { source: 'crease-board:draw' }));
    this.draft = [];
    if (command) this.pending.push({ points, curved, assignment, command });
    this._render();
  }

  _cancelDraft() {
    this.draft = [];
    this.pointer = null;
    this.snap = null;
    this._renderOverlay();
  }

  // ---- keyboard -------------------------------------------------------------------------------

  /** Keys while the board is open (the editor asks first); true when the key was used. */
  handleKey(e) {
    if (!this.isOpen) return false;
    const t = e.target;
    if (t && (t.tagName === 'INPUT' || t.tagName === 'TEXTAREA' || t.tagName === 'SELECT' || t.isContentEditable)) return false;
    if (e.ctrlKey || e.metaKey) return false;
    const key = e.key;
    if (key === 'Escape') {
      if (this.drag) this._cancelDrag();
      else if (this.draft.length) this._cancelDraft();
      else if (this.selected !== null) {
        this._select(null);
        this._render();
      } else this.close();
    } else if (key === 'Enter' && this.tool === 'curve') {
      this.finishDraft();
    } else if (key === 'Backspace' && this.draft.length) {
      this.draft.pop();
      this._renderOverlay();
    } else if ((key === 'Delete' || key === 'Backspace') && this.tool === 'select') {
      if (this._selectedCrease()) this.eraseSelected();
      else if (this.selected !== null) this._setHint('The sheet’s outline is not editable.', true);
    } else {
      return false;
    }
    e.preventDefault();
    return true;
  }

  // ---- drawing --------------------------------------------------------------------------------

  _view() {
    const v = this.board.view;
    v.selected = this.selected;
    v.selectedPoint = this.selectedPoint;
    v.handles = this.tool === 'select' && !!this._selectedCrease();
    v.edit = this.drag && this.drag.moved ? { index: this.drag.index, points: this.drag.points } : this.edit;
    v.pending = this.pending;
    v.draft = this.tool === 'select' ? null : { points: this.draft, pointer: this.draft.length ? this.pointer : null, assignment: this.defaults.assignment, curved: this.tool === 'curve' };
    v.snap = this.snap;
    v.conflicts = this.conflicts;
  }

  _render() {
    this._view();
    this.board.renderStrokes();
  }

  _renderOverlay() {
    this._view();
    this.board.renderOverlay();
  }
}
