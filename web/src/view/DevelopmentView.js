// The development (the strip unrolled into the plane, `geometry.development`): a 2D canvas,
// quads filled with the warp colour, boundary a/b in the curve colours, fitted to the panel.
// Composites show their crease pattern instead: the sheet as paper, mountain folds red dash-dot,
// valley folds blue dashed, boundary black, rulings and flat edges faint (the SVG export's
// conventions). The container's data-polygons / data-creases count what was drawn.
// The fit is kept while the drawing still fills the panel reasonably, so a drag does not make
// the picture jump at every iterate; double-click refits.

import { colorAt } from '../geometry/colormap.js';
import { PATCH_TYPE_COLORS } from '../geometry/StripBuffers.js';
import { CanvasPanel, fitStillFills } from './CanvasPanel.js';

const MARGIN = 14;
/** Height kept clear above a crease pattern for its line key (px). */
const KEY_BAND = 16;

function css(rgb, alpha = 1) {
  return `rgba(${Math.round(rgb[0] * 255)}, ${Math.round(rgb[1] * 255)}, ${Math.round(rgb[2] * 255)}, ${alpha})`;
}

export class DevelopmentView extends CanvasPanel {
  constructor(container, deps) {
    super(container, 'development-canvas');
    this.buffers = deps.buffers;
    this.composite = deps.composite || null;
    /** 'strip' | 'composite'. */
    this.kind = 'strip';
    this.highContrast = false;
    /** What one coordinate is (the scene's units), for the scale bar. */
    this.units = 'mm';
    this._rgb = [0, 0, 0];
    this.canvas.addEventListener('dblclick', () => this.refit());
    this._observeResize();
  }

  /** Bounding box of the development, in the rotated frame if `rotate`. */
  _bounds(v, n, rotate) {
    let x0 = Infinity, y0 = Infinity, x1 = -Infinity, y1 = -Infinity;
    for (let i = 0; i < n; i++) {
      const x = rotate ? -v[2 * i + 1] : v[2 * i];
      const y = rotate ? v[2 * i] : v[2 * i + 1];
      if (x < x0) x0 = x;
      if (x > x1) x1 = x;
      if (y < y0) y0 = y;
      if (y > y1) y1 = y;
    }
    return { x0, y0, x1, y1 };
  }

  /**
   * The bands the drawing keeps clear: the scale bar below; a crease pattern's line key above (a
   * sheet as wide as the panel ran under "mountain – valley").
   */
  _bands() {
    return { top: this.kind === 'composite' ? KEY_BAND : 0, bottom: 14 };
  }

  /** The vertical centre of the drawing area (between the bands). */
  _centreY() {
    const { top, bottom } = this._bands();
    return top + (this.height - top - bottom) / 2;
  }

  _fit(v, n) {
    const { top, bottom } = this._bands();
    const W = this.width - 2 * MARGIN;
    const H = this.height - 2 * MARGIN - top - bottom;
    let best = null;
    // Lay the strip along the panel's long side.
    for (const rotate of [false, true]) {
      const b = this._bounds(v, n, rotate);
      const bw = Math.max(b.x1 - b.x0, 1e-9);
      const bh = Math.max(b.y1 - b.y0, 1e-9);
      const scale = Math.min(W / bw, H / bh);
      if (!best || scale > best.scale * 1.05) best = { rotate, scale, cx: (b.x0 + b.x1) / 2, cy: (b.y0 + b.y1) / 2 };
    }
    return best;
  }

  /** Keeps the current fit if everything is inside the panel and fills ≥ 80% of it. */
  _fitStillGood(v, n) {
    const t = this.transform;
    if (!t) return false;
    const { top, bottom } = this._bands();
    return fitStillFills(this._bounds(v, n, t.rotate), t, this.width - 2 * MARGIN, this.height - 2 * MARGIN - top - bottom, 0.8);
  }

  setKind(kind) {
    if (kind === this.kind) return;
    this.kind = kind;
    this.transform = null;
    this.render();
  }

  render() {
    const ctx = this.ctx;
    const { width: W, height: H } = this;
    ctx.setTransform(this.dpr, 0, 0, this.dpr, 0, 0);
    ctx.clearRect(0, 0, W, H);
    if (this.kind === 'composite') {
      this._renderCreasePattern();
      return;
    }
    const dev = this.buffers.development;
    const n = dev.count;
    if (!this.buffers.hasData || n === 0) {
      this._message(this.buffers.hasData ? 'no development for this geometry' : 'waiting for geometry…');
      return;
    }
    const v = dev.vertices;
    if (!this._fitStillGood(v, n)) this.transform = this._fit(v, n);
    const t = this.transform;
    const ox = W / 2;
    const oy = this._centreY();
    const X = (i) => ox + ((t.rotate ? -v[2 * i + 1] : v[2 * i]) - t.cx) * t.scale;
    const Y = (i) => oy - ((t.rotate ? v[2 * i] : v[2 * i + 1]) - t.cy) * t.scale;

    // Quads, filled with the warp colour of their vertices.
    const q = dev.quads;
    const warp = this.buffers.warp;
    const range = this.buffers.colorRange;
    const quadValue = dev.quadValue;  // conical strips: one value per unfolded quad
    const categorical = this.buffers.categorical;
    ctx.lineJoin = 'round';
    for (let f = 0; f < q.length; f += 4) {
      const a = q[f], b = q[f + 1], c = q[f + 2], d = q[f + 3];
      if (quadValue && categorical) {
        const rgb = PATCH_TYPE_COLORS[quadValue[f / 4]] || [0.6, 0.6, 0.6];
        this._rgb[0] = rgb[0];
        this._rgb[1] = rgb[1];
        this._rgb[2] = rgb[2];
      } else {
        const w = quadValue ? quadValue[f / 4] : warp.length === n ? (warp[a] + warp[b] + warp[c] + warp[d]) / 4 : 0;
        colorAt(w / range, this._rgb);
      }
      ctx.beginPath();
      ctx.moveTo(X(a), Y(a));
      ctx.lineTo(X(b), Y(b));
      ctx.lineTo(X(c), Y(c));
      ctx.lineTo(X(d), Y(d));
      ctx.closePath();
      ctx.fillStyle = css(this._rgb);
      ctx.fill();
      ctx.strokeStyle = css(this._rgb);
      ctx.lineWidth = 0.6;
      ctx.stroke();
    }

    // Conical strips: every unfolded patch outlined, boundaries in the curve colours.
    if (dev.quadPatch) {
      this._patchOutlines(q, dev.quadPatch, X, Y);
      this._scaleBar(t.scale);
      return;
    }

    // Rulings (the grid's v-lines), every few samples.
    const [U, V] = this.buffers.grid;
    if (U * V === n && V > 1) {
      const every = Math.max(1, Math.round(U / 32));
      ctx.strokeStyle = this.highContrast ? 'rgba(0,0,0,0.8)' : 'rgba(16,19,26,0.45)';
      ctx.lineWidth = 1;
      ctx.beginPath();
      for (let i = 0; i < U; i += every) {
        ctx.moveTo(X(i * V), Y(i * V));
        ctx.lineTo(X(i * V + V - 1), Y(i * V + V - 1));
      }
      ctx.stroke();
      // Boundaries a (j = 0) and b (j = V − 1) in the curve colours.
      for (const [j, color] of [[0, '#ff9f43'], [V - 1, '#48cae4']]) {
        ctx.strokeStyle = color;
        ctx.lineWidth = this.highContrast ? 3 : 2;
        ctx.beginPath();
        for (let i = 0; i < U; i++) {
          const k = i * V + j;
          if (i === 0) ctx.moveTo(X(k), Y(k));
          else ctx.lineTo(X(k), Y(k));
        }
        ctx.stroke();
      }
    }

    this._scaleBar(t.scale);
  }

  /**
   * Outlines of unfolded conical patches: the quads of a patch form a ladder (rungs are rulings,
   * vertex a on P, d on Q); its first and last rungs are the patch's boundary rulings.
   */
  _patchOutlines(q, quadPatch, X, Y) {
    const ctx = this.ctx;
    let patches = 0;
    ctx.strokeStyle = this.highContrast ? 'rgba(0,0,0,0.9)' : 'rgba(16,19,26,0.35)';
    ctx.lineWidth = 1;
    ctx.beginPath();
    for (let f = 0; f < q.length; f += 4) {
      const k = f / 4;
      if (k === 0 || quadPatch[k] !== quadPatch[k - 1]) {
        patches++;
        ctx.moveTo(X(q[f]), Y(q[f]));
        ctx.lineTo(X(q[f + 3]), Y(q[f + 3]));
      }
      if (k + 1 === quadPatch.length || quadPatch[k + 1] !== quadPatch[k]) {
        ctx.moveTo(X(q[f + 1]), Y(q[f + 1]));
        ctx.lineTo(X(q[f + 2]), Y(q[f + 2]));
      }
    }
    ctx.stroke();
    for (const [from, to, color] of [[0, 1, '#ff9f43'], [3, 2, '#48cae4']]) {
      ctx.strokeStyle = color;
      ctx.lineWidth = this.highContrast ? 3 : 2;
      ctx.beginPath();
      for (let f = 0; f < q.length; f += 4) {
        ctx.moveTo(X(q[f + from]), Y(q[f + from]));
        ctx.lineTo(X(q[f + to]), Y(q[f + to]));
      }
      ctx.stroke();
    }
    this.container.dataset.polygons = String(patches);
  }

  /** A composite's crease pattern (CompositeBuffers.development). */
  _renderCreasePattern() {
    const ctx = this.ctx;
    const c = this.composite;
    const dev = c && c.development;
    this.container.dataset.polygons = '0';
    this.container.dataset.creases = '0';
    if (!c || !c.hasData) return this._message('waiting for geometry…');
    if (!dev || dev.count === 0) {
      this._message('no development: add "development": {"samples": 4} to the scene’s model');
      return;
    }
    const v = dev.vertices;
    const n = dev.count;
    if (!this._fitStillGood(v, n)) this.transform = this._fit(v, n);
    const t = this.transform;
    const ox = this.width / 2;
    const oy = this._centreY();
    const X = (i) => ox + ((t.rotate ? -v[2 * i + 1] : v[2 * i]) - t.cx) * t.scale;
    const Y = (i) => oy - ((t.rotate ? v[2 * i] : v[2 * i + 1]) - t.cy) * t.scale;
    const P = (x, y) => [ox + ((t.rotate ? -y : x) - t.cx) * t.scale, oy - ((t.rotate ? x : y) - t.cy) * t.scale];

    // The sheet: paper, faces tinted lightly by the surface colour field where it is large.
    const tri = dev.triangles;
    const paper = this.highContrast ? '#ffffff' : '#f3eee3';
    ctx.fillStyle = paper;
    ctx.strokeStyle = paper;
    ctx.lineWidth = 0.8;
    ctx.lineJoin = 'round';
    ctx.beginPath();
    for (let k = 0; k < tri.length; k += 3) {
      ctx.moveTo(X(tri[k]), Y(tri[k]));
      ctx.lineTo(X(tri[k + 1]), Y(tri[k + 1]));
      ctx.lineTo(X(tri[k + 2]), Y(tri[k + 2]));
      ctx.closePath();
    }
    ctx.fill();
    ctx.stroke();

    // Rulings, faint.
    const r = dev.rulings;
    ctx.strokeStyle = 'rgba(60, 64, 72, 0.28)';
    ctx.lineWidth = 0.8;
    ctx.setLineDash([]);
    ctx.beginPath();
    for (let k = 0; k + 3 < r.length; k += 4) {
      const [x0, y0] = P(r[k], r[k + 1]);
      const [x1, y1] = P(r[k + 2], r[k + 3]);
      ctx.moveTo(x0, y0);
      ctx.lineTo(x1, y1);
    }
    ctx.stroke();

    // Edges by assignment, as in the SVG export.
    const styles = {
      F: { color: 'rgba(60, 64, 72, 0.35)', width: 0.8, dash: [1.5, 2.5] },
      B: { color: '#151820', width: this.highContrast ? 2.6 : 1.8, dash: [] },
      M: { color: '#d62828', width: this.highContrast ? 3 : 2.2, dash: [9, 3, 2, 3] },
      V: { color: '#1d6fd6', width: this.highContrast ? 3 : 2.2, dash: [6, 4] },
      C: { color: '#151820', width: 1.8, dash: [] },
    };
    const e = dev.edges;
    let creases = 0;
    for (const letter of ['F', 'B', 'C', 'V', 'M']) {
      const s = styles[letter];
      ctx.strokeStyle = s.color;
      ctx.lineWidth = s.width;
      ctx.setLineDash(s.dash);
      ctx.beginPath();
      let any = false;
      for (let k = 0; k < dev.assignment.length; k++) {
        if (dev.assignment[k] !== letter) continue;
        ctx.moveTo(X(e[2 * k]), Y(e[2 * k]));
        ctx.lineTo(X(e[2 * k + 1]), Y(e[2 * k + 1]));
        any = true;
        if (letter === 'M' || letter === 'V') creases++;
      }
      if (any) ctx.stroke();
    }
    ctx.setLineDash([]);
    this.container.dataset.polygons = String(tri.length / 3);
    this.container.dataset.creases = String(creases);
    this._key();
    this._scaleBar(t.scale);
  }

  /** Line key of the crease pattern (top right). */
  _key() {
    const ctx = this.ctx;
    const items = [['mountain', '#d62828', [9, 3, 2, 3]], ['valley', '#1d6fd6', [6, 4]]];
    ctx.font = `${this.highContrast ? 13 : 11}px system-ui, sans-serif`;
    ctx.textAlign = 'left';
    let x = this.width - 190;
    const y = 14;
    for (const [label, color, dash] of items) {
      ctx.strokeStyle = color;
      ctx.lineWidth = 2.2;
      ctx.setLineDash(dash);
      ctx.beginPath();
      ctx.moveTo(x, y);
      ctx.lineTo(x + 30, y);
      ctx.stroke();
      ctx.setLineDash([]);
      ctx.fillStyle = this.highContrast ? '#ffffff' : '#c9d1dc';
      ctx.fillText(label, x + 36, y + 4);
      x += 95;
    }
  }

  _scaleBar(scale) {
    const ctx = this.ctx;
    const target = 70 / scale;
    const p = Math.pow(10, Math.floor(Math.log10(target)));
    let len = p;
    for (const m of [1, 2, 5]) if (m * p <= target) len = m * p;
    const px = len * scale;
    const x = MARGIN;
    const y = this.height - 8;
    ctx.strokeStyle = this.highContrast ? '#ffffff' : '#c9d1dc';
    ctx.fillStyle = ctx.strokeStyle;
    ctx.lineWidth = 1.5;
    ctx.beginPath();
    ctx.moveTo(x, y - 4);
    ctx.lineTo(x, y);
    ctx.lineTo(x + px, y);
    ctx.lineTo(x + px, y - 4);
    ctx.stroke();
    ctx.font = `${this.highContrast ? 13 : 11}px system-ui, sans-serif`;
    ctx.textAlign = 'left';
    ctx.fillText(`${len >= 1 ? len : len.toPrecision(1)} ${this.units}`, x + px + 6, y + 1);
  }
}
