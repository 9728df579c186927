// The mapping σ of a quasi-developable strip (Bo et al.): t on C1 (x) against T = σ(t) on C2 (y).
// The solver starts from σ(t) = t in the curves' parameters (dashed); the current σ is solid, the
// trimmed range of the strip is shaded. Same look as the residual plot (uPlot).

import uPlot from 'uplot';
import 'uplot/dist/uPlot.min.css';
import { h, clear, formatSignificant } from './dom.js';

export const MAPPING_COLORS = { initial: '#8d99ae', sigma: '#ffd166' };

/** Columns [t[], initial[], sigma[]] of a buffers.mapping ({sigma, initial}: [t, σ] pairs). */
export function mappingColumns(mapping) {
  const n = Math.min(mapping.sigma.length, mapping.initial.length) / 2;
  const t = new Array(n), initial = new Array(n), sigma = new Array(n);
  for (let i = 0; i < n; i++) {
    t[i] = mapping.sigma[2 * i];
    sigma[i] = mapping.sigma[2 * i + 1];
    initial[i] = mapping.initial[2 * i + 1];
  }
  return [t, initial, sigma];
}

/** Largest |σ(t) − σ0(t)| over the samples (how far the solve moved the mapping). */
export function mappingChange(columns) {
  const [, initial, sigma] = columns;
  let d = 0;
  for (let i = 0; i < sigma.length; i++) d = Math.max(d, Math.abs(sigma[i] - initial[i]));
  return d;
}

export class MappingPlot {
  /**
   * @param {HTMLElement} parent
   * @param {object} deps {buffers: StripBuffers (its `mapping`)}
   */
  constructor(parent, { buffers }) {
    this.buffers = buffers;
    this.large = false;
    this.legend = h('div', { class: 'plot-legend' },
      h('span', { class: 'plot-key' }, h('span', { class: 'plot-swatch plot-swatch-dashed', style: { borderColor: MAPPING_COLORS.initial } }), 'initial σ(t) = t'),
      h('span', { class: 'plot-key' }, h('span', { class: 'plot-swatch', style: { background: MAPPING_COLORS.sigma } }), 'σ after solving'),
      this.change = h('span', { class: 'plot-key muted' }, ''));
    this.container = h('div', { class: 'plot-area', testid: 'mapping-plot' });
    this.container.dataset.points = '0';
    this.placeholder = h('div', { class: 'plot-placeholder' }, 'waiting for the mapping…');
    this.container.appendChild(this.placeholder);
    parent.append(this.legend, this.container);
    this.plot = null;
    this._resizeObserver = new ResizeObserver(() => this._resize());
    this._resizeObserver.observe(this.container);
  }

  setLarge(large) {
    this.large = large;
    if (this.plot) {
      this.plot.destroy();
      this.plot = null;
    }
    this.update();
  }

  _size() {
    return { width: Math.max(120, this.container.clientWidth - 4), height: Math.max(80, this.container.clientHeight - 4) };
  }

  _resize() {
    if (this.plot) this.plot.setSize(this._size());
  }

  update() {
    const m = this.buffers.mapping;
    if (!m) return;
    const data = mappingColumns(m);
    this.change.textContent = `max |σ − t| ${formatSignificant(mappingChange(data), 3)}`;
    this.container.dataset.points = String(data[0].length);
    if (this.plot) {
      this.plot.setData(data);
      return;
    }
    clear(this.container);
    const font = this.large ? '13px system-ui, sans-serif' : '11px system-ui, sans-serif';
    const axis = { stroke: '#aeb7c4', font, grid: { stroke: 'rgba(255,255,255,0.07)', width: 1 }, ticks: { stroke: 'rgba(255,255,255,0.15)', width: 1 } };
    const trimHook = (u) => {
      // The trimmed range of the strip, shaded.
      const trim = this.buffers.mapping && this.buffers.mapping.trim;
      if (!trim) return;
      const x0 = u.valToPos(trim[0], 'x', true), x1 = u.valToPos(trim[1], 'x', true);
      const { top, height } = u.bbox;
      u.ctx.save();
      u.ctx.fillStyle = 'rgba(255, 209, 102, 0.06)';
      u.ctx.fillRect(Math.min(x0, x1), top, Math.abs(x1 - x0), height);
      u.ctx.restore();
    };
    this.plot = new uPlot({
      ...this._size(),
      class: 'mapping-uplot',
      legend: { show: false },
      cursor: { drag: { x: false, y: false }, points: { show: false } },
      scales: { x: { time: false } },
      axes: [
        { ...axis, size: this.large ? 34 : 28, label: 't on C1', labelSize: this.large ? 18 : 14, labelFont: font },
        { ...axis, size: this.large ? 56 : 46, label: 'σ(t) on C2', labelSize: this.large ? 18 : 14, labelFont: font },
      ],
      hooks: { drawClear: [trimHook] },
      series: [
        { label: 't' },
        { label: 'initial', stroke: MAPPING_COLORS.initial, width: this.large ? 2 : 1.4, dash: [6, 5], points: { show: false } },
        { label: 'σ', stroke: MAPPING_COLORS.sigma, width: this.large ? 2.6 : 2, points: { show: false } },
      ],
    }, data, this.container);
  }
}
