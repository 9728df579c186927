// What the 2D canvas panels (DevelopmentView, UnfoldingView) share: a canvas filling the
// container at the device pixel ratio (capped at 2), resized with the container; a fit
// (`transform`) that is forgotten on resize and refit and recomputed by the next render; the
// rule for keeping an automatic fit while the drawing still fills the panel; a centred message.

export class CanvasPanel {
  /**
   * Creates the canvas (CSS class `className`) in `container`. A subclass calls _observeResize()
   * at the end of its constructor (it sizes the canvas and renders for the first time).
   */
  constructor(container, className) {
    this.container = container;
    this.canvas = document.createElement('canvas');
    this.canvas.className = className;
    container.appendChild(this.canvas);
    this.ctx = this.canvas.getContext('2d');
    this.transform = null;
  }

  _observeResize() {
    this._resizeObserver = new ResizeObserver(() => this.resize());
    this._resizeObserver.observe(this.container);
    this.resize();
  }

  /** Sizes the canvas to the container (width, height in CSS px; dpr) and renders a new fit. */
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

  /** Forgets the fit (the next render fits the drawing to the panel again). */
  refit() {
    this.transform = null;
    this.render();
  }

  /** A grey line of text in the middle of the panel (no data yet, nothing to draw). */
  _message(text) {
    const ctx = this.ctx;
    ctx.fillStyle = '#8893a5';
    ctx.font = '13px system-ui, sans-serif';
    ctx.textAlign = 'center';
    ctx.fillText(text, this.width / 2, this.height / 2);
  }

  dispose() {
    this._resizeObserver.disconnect();
  }
}

/**
 * Whether a fit may stay: the bounding box `b` ({x0, y0, x1, y1}, drawing units) drawn with `t`
 * ({scale, cx, cy}: px per unit, drawing point at the centre of the area) lies inside the area of
 * W × H px (1 px slack) and fills at least `fill` (0..1) of its width or of its height.
 */
export function fitStillFills(b, t, W, H, fill) {
  const w = (b.x1 - b.x0) * t.scale;
  const h = (b.y1 - b.y0) * t.scale;
  const inside = Math.abs(((b.x0 + b.x1) / 2 - t.cx) * t.scale) + w / 2 <= W / 2 + 1
    && Math.abs(((b.y0 + b.y1) / 2 - t.cy) * t.scale) + h / 2 <= H / 2 + 1;
  return inside && (w >= fill * W || h >= fill * H);
}
