// Live residual plot (uPlot): every term of iterate.residuals over the last iterations, log scale.

import uPlot from 'uplot';
import 'uplot/dist/uPlot.min.css';
import { h, clear } from './dom.js';
import { decadeRange, decadeSplits } from './logScale.js';

const TERM_COLORS = {
  developability: '#ff6b6b',
  fairness: '#ffd166',
  handle: '#ff4fd8',
  unit_normal: '#48cae4',
  unit_normal_hard: '#90be6d',
};
const EXTRA = ['#b388eb', '#f4a261', '#2ec4b6', '#e9ecef'];

function superscript(n) {
  const map = { '-': '⁻', 0: '⁰', 1: '¹', 2: '²', 3: '³', 4: '⁴', 5: '⁵', 6: '⁶', 7: '⁷', 8: '⁸', 9: '⁹' };
  return String(n).split('').map((c) => map[c] || c).join('');
}

export class ResidualPlot {
  constructor(parent, { state }) {
    this.legend = document.createElement('div');
    this.legend.className = 'plot-legend';
    const container = document.createElement('div');
    container.className = 'plot-area';
    parent.append(this.legend, container);
    this.container = container;
    this.state = state;
    this.plot = null;
    this.terms = [];
    this.large = false;
    this.placeholder = h('div', { class: 'plot-placeholder' }, 'No iterations yet: drag a control point or press S to solve.');
    container.appendChild(this.placeholder);
    this._raf = 0;
    state.on('iterate', () => this._schedule());
    this._resizeObserver = new ResizeObserver(() => this._resize());
    this._resizeObserver.observe(container);
  }

  setLarge(large) {
    this.large = large;
    this._rebuild();
  }

  _schedule() {
    if (this._raf) return;
    this._raf = requestAnimationFrame(() => {
      this._raf = 0;
      this.update();
    });
  }

  _size() {
    return { width: Math.max(120, this.container.clientWidth - 4), height: Math.max(80, this.container.clientHeight - 4) };
  }

  _resize() {
    if (this.plot) this.plot.setSize(this._size());
  }

  _rebuild() {
    if (this.plot) {
      this.plot.destroy();
      this.plot = null;
    }
    this.update();
  }

  update() {
    const hist = this.state.residualHistory;
    if (hist.x.length === 0) return;
    const names = Object.keys(hist.terms);
    if (!this.plot || names.join() !== this.terms.join()) {
      this.terms = names;
      if (this.plot) this.plot.destroy();
      clear(this.container);
      clear(this.legend);
      names.forEach((name, i) => {
        const color = TERM_COLORS[name] || EXTRA[i % EXTRA.length];
        this.legend.appendChild(h('span', { class: 'plot-key' }, h('span', { class: 'plot-swatch', style: { background: color } }), name.replace(/_/g, ' ')));
      });
      const font = this.large ? '13px system-ui, sans-serif' : '11px system-ui, sans-serif';
      const axis = { stroke: '#aeb7c4', font, grid: { stroke: 'rgba(255,255,255,0.07)', width: 1 }, ticks: { stroke: 'rgba(255,255,255,0.15)', width: 1 } };
      this.plot = new uPlot({
        ...this._size(),
        class: 'residual-uplot',
        legend: { show: false },
        cursor: { drag: { x: false, y: false }, points: { show: false } },
        scales: {
          x: { time: false },
          y: { distr: 3, log: 10, range: (u) => decadeRange(u.data.slice(1)) },
        },
        axes: [
          { ...axis, size: this.large ? 30 : 24, incrs: [1, 2, 5, 10, 20, 50, 100, 200, 500, 1000] },
          {
            ...axis,
            size: this.large ? 56 : 46,
            filter: (u, splits) => splits,
            splits: (u, i, min, max) => decadeSplits(min, max, Math.max(3, Math.floor(this.container.clientHeight / 26))),
            values: (u, vals) => vals.map((v) => (v ? `10${superscript(Math.round(Math.log10(v)))}` : '')),
          },
        ],
        series: [
          { label: 'iteration' },
          ...names.map((name, i) => ({
            label: name.replace(/_/g, ' '),
            stroke: TERM_COLORS[name] || EXTRA[i % EXTRA.length],
            width: this.large ? 2.2 : 1.5,
            spanGaps: false,
            points: { show: false },
          })),
        ],
      }, [hist.x, ...names.map((n) => hist.terms[n])], this.container);
      return;
    }
    this.plot.setData([hist.x, ...names.map((n) => hist.terms[n])]);
  }
}
