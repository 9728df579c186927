// The unfolding M′ of a quad_mesh session, drawn flat on a 2D canvas beside the 3D view of M (x, y
// of M′; a non-planar M′ is shown from above): faces in the colour mode's face colours, edges in
// its edge colours (boundary edges heavier), glued pairs as numbered green links, handles and
// fixed vertices of M′, the selection of either mesh. Wheel zooms at the pointer, dragging empty
// paper pans, double-click refits. Vertices are picked within a few pixels: a press goes first to
// `pointDown` (gluing picks), else selects the vertex and — when M′ is variable — drags it with
// the same latest-wins coalescing as the 3D view (one DragCommand per animation frame, a
// DragEndCommand on release). The container's data-faces / data-glue count what was drawn.

import { targetKey } from '../commands/Command.js';
import { CanvasPanel, fitStillFills } from './CanvasPanel.js';
import { DragCommandStream } from './DragCommandStream.js';

const MARGIN = 16;
const PICK_PX = 9;
const GLUE = '#5ee6a0';
const HANDLE = '#ff4fd8';
const SELECTED = '#ffd60a';

const css = (c, o = 0) => `rgb(${Math.round(c[o] * 255)}, ${Math.round(c[o + 1] * 255)}, ${Math.round(c[o + 2] * 255)})`;

export class UnfoldingView extends CanvasPanel {
  /** @param {object} deps {state, quad (QuadMeshBuffers), send(command), select(target|null), pointDown(target) → bool, glueFirst() → vertex|null} */
  constructor(container, deps) {
    super(container, 'unfolding-canvas');
    this.state = deps.state;
    this.quad = deps.quad;
    this.send = deps.send;
    this.select = deps.select;
    this.pointDown = deps.pointDown || (() => false);
    this.glueFirst = deps.glueFirst || (() => null);
    this.drag = null;
    this.pan = null;
    this.hovered = null;
    this.visible = false;
    this._bindPointer();
    if (this.state) this.state.on('editable', (editable) => { if (!editable) this._abandonDrag(); });
    this._observeResize();
  }

  setVisible(visible) {
    this.visible = visible;
    if (visible) this.resize();
  }

  _bounds() {
    const u = this.quad.unfolding;
    let x0 = Infinity, y0 = Infinity, x1 = -Infinity, y1 = -Infinity;
    for (let i = 0; i < u.length; i += 3) {
      if (u[i] < x0) x0 = u[i];
      if (u[i] > x1) x1 = u[i];
      if (u[i + 1] < y0) y0 = u[i + 1];
      if (u[i + 1] > y1) y1 = u[i + 1];
    }
    return { x0, y0, x1, y1 };
  }

  _fit() {
    const b = this._bounds();
    const W = this.width - 2 * MARGIN, H = this.height - 2 * MARGIN - 16;
    const scale = Math.min(W / Math.max(b.x1 - b.x0, 1e-9), H / Math.max(b.y1 - b.y0, 1e-9));
    return { scale, cx: (b.x0 + b.x1) / 2, cy: (b.y0 + b.y1) / 2, auto: true };
  }

  /** An automatic fit is kept while M′ stays inside the panel and fills ≥ 70% of it (no jumps while dragging). */
  _fitStillGood() {
    const t = this.transform;
    if (!t) return false;
    if (!t.auto) return true;
    return fitStillFills(this._bounds(), t, this.width - 2 * MARGIN, this.height - 2 * MARGIN - 16, 0.7);
  }

  /** CSS px (relative to the container) of M′ point (x, y). */
  toScreen(x, y) {
    const t = this.transform;
    return { x: this.width / 2 + (x - t.cx) * t.scale, y: (this.height - 16) / 2 - (y - t.cy) * t.scale };
  }

  fromScreen(sx, sy) {
    const t = this.transform;
    return { x: t.cx + (sx - this.width / 2) / t.scale, y: t.cy - (sy - (this.height - 16) / 2) / t.scale };
  }

  /** CSS px position of vertex i of M′ (relative to the container), or null. */
  vertexScreenPosition(i) {
    const q = this.quad;
    if (!q.hasData || !this.transform || i < 0 || i >= q.vertexCount) return null;
    return this.toScreen(q.unfolding[3 * i], q.unfolding[3 * i + 1]);
  }

  render() {
    const ctx = this.ctx;
    const { width: W, height: H } = this;
    ctx.setTransform(this.dpr, 0, 0, this.dpr, 0, 0);
    ctx.clearRect(0, 0, W, H);
    const q = this.quad;
    if (!this.visible) return;
    if (!q.hasData) {
      this._message('waiting for geometry…');
      return;
    }
    if (!this._fitStillGood()) this.transform = this._fit();
    const u = q.unfolding;
    const P = (i) => this.toScreen(u[3 * i], u[3 * i + 1]);
    ctx.lineJoin = 'round';

    // Faces.
    const F = q.faceCount;
    for (let f = 0; f < F; f++) {
      const n = q.faces[4 * f + 3] >= 0 ? 4 : 3;
      ctx.beginPath();
      for (let k = 0; k < n; k++) {
        const p = P(q.faces[4 * f + k]);
        if (k === 0) ctx.moveTo(p.x, p.y);
        else ctx.lineTo(p.x, p.y);
      }
      ctx.closePath();
      ctx.fillStyle = css(q.faceColors, 3 * f);
      ctx.fill();
    }
    // Edges: interior thin, boundary (the cuts) heavy.
    const E = q.edgeCount;
    for (const boundary of [0, 1]) {
      ctx.lineWidth = boundary ? 2 : 1;
      for (let e = 0; e < E; e++) {
        if ((q.edgeBoundary[e] ? 1 : 0) !== boundary) continue;
        const a = P(q.edges[2 * e]), b = P(q.edges[2 * e + 1]);
        ctx.strokeStyle = css(q.edgeColors, 3 * e);
        ctx.beginPath();
        ctx.moveTo(a.x, a.y);
        ctx.lineTo(b.x, b.y);
        ctx.stroke();
      }
    }
    const glue = this._drawGlue(P);
    this._drawVertices(P);
    ctx.fillStyle = '#8893a5';
    ctx.font = '11px system-ui, sans-serif';
    ctx.textAlign = 'left';
    ctx.fillText(`M′ (unfolding${q.planar ? '' : ', seen from above'})${q.unfoldingVariable ? ' · drag vertices' : ''} · wheel zoom · double-click refit`, 8, H - 6);
    this.container.dataset.faces = String(F);
    this.container.dataset.glue = String(glue);
  }

  /** Glued pairs (on M and on M′) as links between the two vertices of M′, numbered pair by pair. */
  _drawGlue(P) {
    const ctx = this.ctx;
    const q = this.quad;
    const lists = [q.glue, q.glueUnfolding];
    const total = (q.glue.length + q.glueUnfolding.length) / 2;
    let k = 0;
    ctx.lineWidth = 1.5;
    ctx.font = '10px system-ui, sans-serif';
    ctx.textAlign = 'center';
    for (const list of lists) {
      for (let g = 0; g + 1 < list.length; g += 2) {
        const a = P(list[g]), b = P(list[g + 1]);
        ctx.strokeStyle = GLUE;
        ctx.setLineDash(list === q.glueUnfolding ? [4, 3] : []);
        ctx.beginPath();
        ctx.moveTo(a.x, a.y);
        ctx.lineTo(b.x, b.y);
        ctx.stroke();
        k++;
        if (total <= 40) {
          ctx.fillStyle = GLUE;
          for (const p of [a, b]) ctx.fillText(String(k), p.x + 7, p.y - 5);
        }
      }
    }
    ctx.setLineDash([]);
    return k;
  }

  _drawVertices(P) {
    const ctx = this.ctx;
    const q = this.quad;
    const st = this.state;
    const unfoldingKeys = (list) => new Set(list.map((x) => targetKey(x)).filter((key) => key.startsWith('u')));
    const fixed = unfoldingKeys(st.constraints.fixed);
    const handles = st.constraints.handles.filter((h) => targetKey(h).startsWith('u'));
    const sel = st.selection;
    const first = this.glueFirst();
    const dot = (p, r, fill, stroke) => {
      ctx.beginPath();
      ctx.arc(p.x, p.y, r, 0, 2 * Math.PI);
      ctx.fillStyle = fill;
      ctx.fill();
      if (stroke) {
        ctx.strokeStyle = stroke;
        ctx.lineWidth = 1.5;
        ctx.stroke();
      }
    };
    for (let i = 0; i < q.vertexCount; i++) {
      const glued = q.glued[i] === 1;
      if (q.boundary[i] || glued) dot(P(i), glued ? 2.6 : 1.8, glued ? GLUE : '#f4f6f8');
    }
    for (const key of fixed) {
      const p = P(Number(key.slice(1)));
      ctx.fillStyle = '#8d99ae';
      ctx.fillRect(p.x - 4, p.y - 4, 8, 8);
    }
    ctx.lineWidth = 1.2;
    for (const h of handles) {
      const i = (h.target || h).vertex;
      const p = P(i);
      dot(p, 4, HANDLE);
      if (h.position) {
        const t = this.toScreen(h.position[0], h.position[1]);
        ctx.strokeStyle = HANDLE;
        ctx.beginPath();
        ctx.moveTo(p.x, p.y);
        ctx.lineTo(t.x, t.y);
        ctx.stroke();
        ctx.strokeRect(t.x - 4, t.y - 4, 8, 8);
      }
    }
    if (this.hovered !== null && this.hovered < q.vertexCount) dot(P(this.hovered), 5, 'rgba(255,255,255,0.35)', '#ffffff');
    if (first !== null && first !== undefined && first < q.vertexCount) dot(P(first), 6, 'rgba(94,230,160,0.35)', GLUE);
    // A selected control point of a spline surface has no vertex of M′.
    if (sel && sel.vertex !== undefined && sel.on !== 'control' && sel.vertex < q.vertexCount) dot(P(sel.vertex), 5, SELECTED, '#000000');
  }

  // ---- picking, dragging, zoom and pan --------------------------------------------------------

  _local(e) {
    const r = this.canvas.getBoundingClientRect();
    return { x: e.clientX - r.left, y: e.clientY - r.top };
  }

  /** The vertex of M′ nearest the pointer within PICK_PX (glue mode: boundary vertices only), or null. */
  pick(e, filter = null) {
    const q = this.quad;
    if (!q.hasData || !this.transform) return null;
    const s = this._local(e);
    let best = null;
    let bestD = PICK_PX;
    for (let i = 0; i < q.vertexCount; i++) {
      if (filter && !filter(i)) continue;
      const p = this.toScreen(q.unfolding[3 * i], q.unfolding[3 * i + 1]);
      const d = Math.hypot(p.x - s.x, p.y - s.y);
      if (d < bestD) {
        bestD = d;
        best = i;
      }
    }
    return best;
  }

  _bindPointer() {
    const c = this.canvas;
    c.addEventListener('pointerdown', (e) => this._onDown(e));
    c.addEventListener('pointermove', (e) => this._onMove(e));
    c.addEventListener('pointerup', (e) => this._onUp(e));
    c.addEventListener('pointercancel', (e) => this._onUp(e));
    c.addEventListener('dblclick', () => this.refit());
    c.addEventListener('wheel', (e) => {
      if (!this.transform) return;
      e.preventDefault();
      const s = this._local(e);
      const before = this.fromScreen(s.x, s.y);
      const t = this.transform;
      t.scale *= Math.exp(-e.deltaY * 0.0015);
      t.auto = false;
      const after = this.fromScreen(s.x, s.y);
      t.cx += before.x - after.x;
      t.cy += before.y - after.y;
      this.render();
    }, { passive: false });
  }

  _onDown(e) {
    if (e.button !== 0 || !this.quad.hasData) return;
    const i = this.pick(e);
    try { this.canvas.setPointerCapture(e.pointerId); } catch { /* synthetic events */ }
    if (i === null) {
      this.pan = { pointerId: e.pointerId, start: this._local(e), moved: false, t: { ...this.transform } };
      return;
    }
    e.preventDefault();
    const target = { vertex: i, on: 'unfolding' };
    if (this.pointDown(target)) {
      this.render();
      return;
    }
    const q = this.quad;
    const draggable = q.unfoldingVariable && this.state.canEdit;
    this.select(draggable ? target : { vertex: i });
    if (!draggable) {
      this.render();
      return;
    }
    const s = this._local(e);
    const p = this.fromScreen(s.x, s.y);
    this.drag = {
      target, pointerId: e.pointerId, z: q.unfolding[3 * i + 2],
      offset: { x: q.unfolding[3 * i] - p.x, y: q.unfolding[3 * i + 1] - p.y },
      commands: new DragCommandStream((c) => this.send(c), target, 'unfolding'),
    };
    this.canvas.style.cursor = 'grabbing';
    this.render();
  }

  _onMove(e) {
    const d = this.drag;
    if (d) {
      if (e.pointerId !== d.pointerId) return;
      const s = this._local(e);
      const p = this.fromScreen(s.x, s.y);
      d.commands.move([p.x + d.offset.x, p.y + d.offset.y, this.quad.planar ? 0 : d.z]);
      return;
    }
    const pan = this.pan;
    if (pan) {
      if (e.pointerId !== pan.pointerId) return;
      const s = this._local(e);
      if (Math.hypot(s.x - pan.start.x, s.y - pan.start.y) > 3) pan.moved = true;
      if (pan.moved) {
        this.transform = { ...pan.t, auto: false, cx: pan.t.cx - (s.x - pan.start.x) / pan.t.scale, cy: pan.t.cy + (s.y - pan.start.y) / pan.t.scale };
        this.render();
      }
      return;
    }
    if (e.buttons) return;
    const i = this.pick(e);
    if (i !== this.hovered) {
      this.hovered = i;
      this.canvas.style.cursor = i === null ? '' : 'pointer';
      this.render();
    }
  }

  /** The connection dropped mid-drag: the drag ends, nothing more is sent. */
  _abandonDrag() {
    const d = this.drag;
    if (!d) return;
    d.commands.abandon();
    this.drag = null;
    try { this.canvas.releasePointerCapture(d.pointerId); } catch { /* ignore */ }
    this.canvas.style.cursor = '';
    this.render();
  }

  _onUp(e) {
    try { this.canvas.releasePointerCapture(e.pointerId); } catch { /* ignore */ }
    const d = this.drag;
    if (d && e.pointerId === d.pointerId) {
      d.commands.end();
      this.drag = null;
      this.canvas.style.cursor = '';
      this.render();
      return;
    }
    const pan = this.pan;
    if (pan && e.pointerId === pan.pointerId) {
      this.pan = null;
      if (!pan.moved && this.state.selection) this.select(null);
    }
  }
}
