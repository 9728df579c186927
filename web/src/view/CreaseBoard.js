// The crease-pattern drawing board's picture: an SVG filling its container with the sheet as
// paper (a faint grid on it), the drawing's strokes in Origami Simulator's colours (outline
// black, mountain red, valley blue, flat yellow, cut green), the selected stroke highlighted with
// its points as handles, and what is being drawn: the draft, strokes sent and not yet applied,
// the snap marker. The sheet is fitted to the board (refit on resize and when the sheet changes).
// The SVG's data-strokes counts the strokes drawn, data-selected names the selected one.
// Interaction lives in ui/CreaseBoardPanel.js; the maths in geometry/creaseDrawing.js.

import {
  STROKE_STYLES, fitTransform, gridStep, outlineLoops, sheetBounds, strokeGeometry, strokePolyline, toScreen, toSheet,
} from '../geometry/creaseDrawing.js';

const SVG_NS = 'http://www.w3.org/2000/svg';
const MARGIN = 28;
const HIGHLIGHT = '#ffb703';
const SNAP_COLOR = '#ff6d00';

function el(tag, attrs = {}) {
  const e = document.createElementNS(SVG_NS, tag);
  for (const [k, v] of Object.entries(attrs)) if (v !== undefined && v !== null) e.setAttribute(k, String(v));
  return e;
}

const f = (x) => (Math.round(x * 100) / 100).toString();

export class CreaseBoard {
  constructor(container) {
    this.container = container;
    this.svg = el('svg', { class: 'crease-board-svg', 'data-testid': 'crease-board', 'data-strokes': '0', role: 'img', 'aria-label': 'Crease pattern' });
    this.defs = el('defs');
    this.clip = el('clipPath', { id: `crease-sheet-clip-${Math.random().toString(36).slice(2)}` });
    this.defs.appendChild(this.clip);
    this.sheetLayer = el('g', { class: 'sheet' });
    this.gridLayer = el('g', { class: 'grid', 'clip-path': `url(#${this.clip.id})` });
    this.strokeLayer = el('g', { class: 'strokes' });
    this.overlayLayer = el('g', { class: 'overlay' });
    this.svg.append(this.defs, this.sheetLayer, this.gridLayer, this.strokeLayer, this.overlayLayer);
    container.appendChild(this.svg);
    this.strokes = [];
    this.geometry = [];
    this.loops = [];
    this.bounds = null;
    this.transform = null;
    this.width = 1;
    this.height = 1;
    /** What the controller draws over the strokes (see render). */
    this.view = {};
    this._resizeObserver = new ResizeObserver(() => this.resize());
    this._resizeObserver.observe(container);
  }

  /** The drawing's strokes changed (or were set for the first time). */
  setStrokes(strokes) {
    this.strokes = strokes || [];
    this.geometry = strokeGeometry(this.strokes);
    const b = sheetBounds(this.geometry);
    const diag = b ? Math.hypot(b.x1 - b.x0, b.y1 - b.y0) : 1;
    this.loops = outlineLoops(this.geometry, 1e-4 * diag);
    const same = b && this.bounds && ['x0', 'y0', 'x1', 'y1'].every((k) => Math.abs(b[k] - this.bounds[k]) <= 1e-9 * diag);
    this.bounds = b;
    if (!same) this.transform = null;
    this.renderAll();
  }

  resize() {
    const w = Math.max(1, this.container.clientWidth);
    const ht = Math.max(1, this.container.clientHeight);
    if (w === this.width && ht === this.height && this.transform) return;
    this.width = w;
    this.height = ht;
    this.transform = null;
    this.renderAll();
  }

  /** The fit, made when needed (null while there is nothing to fit or no size). */
  fit() {
    if (!this.transform && this.bounds && this.width > 2 * MARGIN && this.height > 2 * MARGIN) {
      this.transform = fitTransform(this.bounds, this.width, this.height, MARGIN);
    }
    return this.transform;
  }

  /** Sheet point → board px (relative to the SVG), or null. */
  toScreen(p) {
    const t = this.fit();
    return t ? toScreen(t, p) : null;
  }

  /** Board px → sheet point, or null. */
  toSheet(q) {
    const t = this.fit();
    return t ? toSheet(t, q) : null;
  }

  /** Sheet units per screen px. */
  get unitsPerPx() {
    const t = this.fit();
    return t ? 1 / t.scale : 1;
  }

  _path(points, closed = false) {
    const t = this.fit();
    let d = '';
    points.forEach((p, k) => {
      const q = toScreen(t, p);
      d += `${k ? 'L' : 'M'}${f(q[0])} ${f(q[1])}`;
    });
    return closed ? `${d}Z` : d;
  }

  /** Everything: sheet, grid, strokes and the overlay. */
  renderAll() {
    this.svg.setAttribute('data-strokes', String(this.strokes.length));
    this.sheetLayer.replaceChildren();
    this.gridLayer.replaceChildren();
    this.clip.replaceChildren();
    const t = this.fit();
    if (!t) {
      this.strokeLayer.replaceChildren();
      this.overlayLayer.replaceChildren();
      return;
    }
    // The paper, and a faint grid clipped to it.
    const b = this.bounds;
    const sheetD = this.loops.length
      ? this.loops.map((loop) => this._path(loop, true)).join('')
      : this._path([[b.x0, b.y0], [b.x1, b.y0], [b.x1, b.y1], [b.x0, b.y1]], true);
    this.sheetLayer.appendChild(el('path', { d: sheetD, class: 'crease-sheet', 'fill-rule': 'evenodd' }));
    this.clip.appendChild(el('path', { d: sheetD, 'clip-rule': 'evenodd' }));
    const step = gridStep(t.scale);
    let grid = '';
    for (let x = Math.ceil(b.x0 / step) * step; x <= b.x1; x += step) grid += `M${f(toScreen(t, [x, b.y0])[0])} ${f(toScreen(t, [x, b.y0])[1])}V${f(toScreen(t, [x, b.y1])[1])}`;
    for (let y = Math.ceil(b.y0 / step) * step; y <= b.y1; y += step) grid += `M${f(toScreen(t, [b.x0, y])[0])} ${f(toScreen(t, [b.x0, y])[1])}H${f(toScreen(t, [b.x1, y])[0])}`;
    if (grid) this.gridLayer.appendChild(el('path', { d: grid, class: 'crease-grid' }));
    this.gridStep = step;
    this.renderStrokes();
  }

  /** The strokes (and the overlay, which depends on them). */
  renderStrokes() {
    const t = this.fit();
    this.strokeLayer.replaceChildren();
    if (!t) return;
    const v = this.view;
    const edited = v.edit ? v.edit.index : -1;
    const order = ['F', 'B', 'C', 'V', 'M'];
    const sorted = this.geometry.slice().sort((a, b) => order.indexOf(a.assignment) - order.indexOf(b.assignment));
    if (v.selected !== null && v.selected !== undefined && this.geometry[v.selected]) {
      const g = this.geometry[v.selected];
      const line = edited === g.index ? strokePolyline({ ...this.strokes[g.index], points: v.edit.points }).points : g.polyline;
      this.strokeLayer.appendChild(el('path', { d: this._path(line), class: 'crease-highlight', stroke: HIGHLIGHT }));
    }
    for (const g of sorted) {
      const style = STROKE_STYLES[g.assignment] || STROKE_STYLES.F;
      const line = edited === g.index ? strokePolyline({ ...this.strokes[g.index], points: v.edit.points }).points : g.polyline;
      this.strokeLayer.appendChild(el('path', {
        d: this._path(line), stroke: style.color, 'stroke-width': style.width, 'stroke-dasharray': style.dash || undefined,
        class: 'crease-stroke', 'data-stroke': g.index, 'data-assignment': g.assignment,
      }));
    }
    this.svg.setAttribute('data-selected', v.selected === null || v.selected === undefined ? '' : String(v.selected));
    this.renderOverlay();
  }

  /**
   * What the controller shows over the strokes (`this.view`): selected (stroke index), edit
   * ({index, points}: a stroke being reshaped), selectedPoint (handle index), handles (bool),
   * draft ({points, assignment, curved, pointer}), pending ([{points, curved, assignment}]),
   * snap ({point, kind}), conflicts ([{point, reason}]: points whose creases cannot all fold).
   */
  renderOverlay() {
    const t = this.fit();
    this.overlayLayer.replaceChildren();
    if (!t) return;
    const v = this.view;
    for (const p of v.pending || []) {
      const style = STROKE_STYLES[p.assignment] || STROKE_STYLES.F;
      const line = strokePolyline({ points: p.points, curved: p.curved }).points;
      this.overlayLayer.appendChild(el('path', { d: this._path(line), stroke: style.color, 'stroke-width': style.width, class: 'crease-pending' }));
    }
    const d = v.draft;
    if (d && (d.points.length || d.pointer)) {
      const style = STROKE_STYLES[d.assignment] || STROKE_STYLES.V;
      const pts = d.pointer ? d.points.concat([d.pointer]) : d.points;
      if (pts.length >= 2) {
        const line = strokePolyline({ points: pts, curved: d.curved && pts.length >= 3 }).points;
        this.overlayLayer.appendChild(el('path', { d: this._path(line), stroke: style.color, 'stroke-width': style.width, 'stroke-dasharray': style.dash || undefined, class: 'crease-draft' }));
      }
      for (const p of d.points) {
        const q = toScreen(t, p);
        this.overlayLayer.appendChild(el('circle', { cx: f(q[0]), cy: f(q[1]), r: 3.5, fill: style.color, class: 'crease-draft-point' }));
      }
    }
    const sel = v.selected;
    if (v.handles && sel !== null && sel !== undefined && this.strokes[sel]) {
      const pts = v.edit && v.edit.index === sel ? v.edit.points : this.strokes[sel].points;
      const closed = !!this.strokes[sel].closed;
      pts.forEach((p, k) => {
        const q = toScreen(t, p);
        const end = !closed && (k === 0 || k === pts.length - 1);
        const attrs = { class: `crease-handle${k === v.selectedPoint ? ' selected' : ''}${end ? ' end' : ''}`, 'data-point': k };
        this.overlayLayer.appendChild(end
          ? el('rect', { ...attrs, x: f(q[0] - 5), y: f(q[1] - 5), width: 10, height: 10 })
          : el('circle', { ...attrs, cx: f(q[0]), cy: f(q[1]), r: 5.5 }));
      });
    }
    for (const c of v.conflicts || []) {
      const q = toScreen(t, c.point);
      const mark = el('circle', { cx: f(q[0]), cy: f(q[1]), r: 10, class: 'crease-conflict', 'data-reason': c.reason });
      const title = el('title');
      title.textContent = c.reason;
      mark.appendChild(title);
      this.overlayLayer.appendChild(mark);
    }
    if (v.snap && v.snap.kind) {
      const q = toScreen(t, v.snap.point);
      this.overlayLayer.appendChild(v.snap.kind === 'vertex'
        ? el('rect', { x: f(q[0] - 7), y: f(q[1] - 7), width: 14, height: 14, class: 'crease-snap', stroke: SNAP_COLOR, 'data-snap': 'vertex' })
        : el('circle', { cx: f(q[0]), cy: f(q[1]), r: 7, class: 'crease-snap', stroke: SNAP_COLOR, 'data-snap': 'stroke' }));
    }
  }

  dispose() {
    this._resizeObserver.disconnect();
  }
}
