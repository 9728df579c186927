// The development (the strip unrolled into the plane, `geometry.development`): a 2D canvas,
// quads filled with the warp colour, boundary a/b in the curve colours, fitted to the panel.
// The fit is kept while the drawing still fills the panel reasonably, so a drag does not make
// the picture jump at every iterate; double-click refits.

import { colorAt } from '../geometry/colormap.js';

const MARGIN = 14;

function css(rgb, alpha = 1) {
  return `rgba(${Math.round(rgb[0] * 255)}, ${Math.round(rgb[1] * 255)}, ${Math.round(rgb[2] * 255)}, ${alpha})`;
}

export class DevelopmentView {
  constructor(container, deps) {
    this.container = container;
    this.buffers = deps.buffers;
    this.canvas = document.createElement('canvas');
    this.canvas.className = 'development-canvas';
    container.appendChild(this.canvas);
    this.ctx = this.canvas.getContext('2d');
    this.transform = null;
    this.highContrast = false;
    this._rgb = [0, 0, 0];
    this.canvas.addEventListener('dblclick', () => {
      this.transform = null;
      this.render();
    });
    this._resizeObserver = new ResizeObserver(() => this.resize());
    this._resizeObserver.observe(container);
    this.resize();
  }

  /** Forgets the fit (the next render fits the drawing to the panel again). */
  refit() {
    this.transform = null;
    this.render();
  }

  resize() {
    const dpr = Math.min(window.devicePixelRatio || 1, 2);
    this.width = Math.max(1, this.container.clientWidth);
    this.height = Math.max(1, this.container.clientHeight);
    this.canvas.width = Math.round(this.width * dpr);
    this.canvas.height = Math.round(this.height * dpr);
    this.canvas.style.width = `${this.width}px`;
    this.canvas.style.height = `${this.height}px`;
    this.dpr = dpr;
    this.transform = null;
    this.render();
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

  _fit(v, n) {
    const W = this.width - 2 * MARGIN;
    const H = this.height - 2 * MARGIN - 14;
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
    const b = this._bounds(v, n, t.rotate);
    const W = this.width - 2 * MARGIN;
    const H = this.height - 2 * MARGIN - 14;
    const w = (b.x1 - b.x0) * t.scale;
    const h = (b.y1 - b.y0) * t.scale;
    const inside = Math.abs(((b.x0 + b.x1) / 2 - t.cx) * t.scale) + w / 2 <= W / 2 + 1 && Math.abs(((b.y0 + b.y1) / 2 - t.cy) * t.scale) + h / 2 <= H / 2 + 1;
    return inside && (w >= 0.8 * W || h >= 0.8 * H);
  }

  render() {
    const ctx = this.ctx;
    const { width: W, height: H } = this;
    ctx.setTransform(this.dpr, 0, 0, this.dpr, 0, 0);
    ctx.clearRect(0, 0, W, H);
    const dev = this.buffers.development;
    const n = dev.count;
    if (!this.buffers.hasData || n === 0) {
      ctx.fillStyle = '#8893a5';
      ctx.font = '13px system-ui, sans-serif';
      ctx.textAlign = 'center';
      ctx.fillText(this.buffers.hasData ? 'no development for this geometry' : 'waiting for geometry…', W / 2, H / 2);
      return;
    }
    const v = dev.vertices;
    if (!this._fitStillGood(v, n)) this.transform = this._fit(v, n);
    const t = this.transform;
    const ox = W / 2;
    const oy = (H - 14) / 2;
    const X = (i) => ox + ((t.rotate ? -v[2 * i + 1] : v[2 * i]) - t.cx) * t.scale;
    const Y = (i) => oy - ((t.rotate ? v[2 * i] : v[2 * i + 1]) - t.cy) * t.scale;

    // Quads, filled with the warp colour of their vertices.
    const q = dev.quads;
    const warp = this.buffers.warp;
    const range = this.buffers.colorRange;
    ctx.lineJoin = 'round';
    for (let f = 0; f < q.length; f += 4) {
      const a = q[f], b = q[f + 1], c = q[f + 2], d = q[f + 3];
      const w = warp.length === n ? (warp[a] + warp[b] + warp[c] + warp[d]) / 4 : 0;
      colorAt(w / range, this._rgb);
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
    ctx.fillText(`${len >= 1 ? len : len.toPrecision(1)} ${len === 1 ? 'unit' : 'units'}`, x + px + 6, y + 1);
  }

  dispose() {
    this._resizeObserver.disconnect();
  }
}
