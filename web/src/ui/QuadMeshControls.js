// The controls of a quad_mesh session (Jiang et al. 2020): the colour mode (L-Err per edge, K, H)
// with the Gauss-image switch, gluing (a mode that picks two boundary vertices in either view and
// sends set_params glue with the pair appended, then a solve; the list of glued pairs with a
// remove button each) and the metrics of Fig. 22 (L-Err, A-Err in %, glue gap, …).

import { h, clear, formatNumber } from './dom.js';
import { QUAD_COLOR_MODES } from '../geometry/QuadMeshBuffers.js';
import { SetParamsCommand } from '../commands/SetParamsCommand.js';
import { SolveCommand } from '../commands/SolveCommand.js';
import { glueCommand, gluePairList, withGluePair, withoutGluePair } from '../commands/glue.js';

const PAIRS_LISTED = 300;

/** A fraction as a percentage with 3 significant digits ('0.0931 %'; tiny values exponential). */
export function percent(x) {
  if (typeof x !== 'number' || !Number.isFinite(x)) return '–';
  const p = 100 * x;
  if (p === 0) return '0 %';
  return `${Math.abs(p) < 1e-3 ? p.toExponential(2) : Number(p.toPrecision(3))} %`;
}

/** Metrics shown for a quad mesh: [metric, label, format, title]. */
const METRICS = [
  ['length_error', 'L-Err', percent, 'Edge length error ‖L′ − L‖/‖L‖ over all edges (Jiang et al. Fig. 22)', 'metric-length-error'],
  ['area_error', 'A-Err', percent, 'Face area error ‖A′ − A‖/‖A‖ over the faces (Fig. 22)', 'metric-area-error'],
  ['glue_gap_max', 'glue gap', (x) => (x === 0 ? '0' : x.toExponential(2)), 'Largest distance of a glued pair ÷ the bounding-box diagonal of M', 'metric-glue-gap'],
  ['isometry_residual_max', 'isometry residual', (x) => x.toExponential(2), 'Largest residual of the checkerboard isometry (eq. 1)', 'metric-isometry'],
  ['handle_distance_max', 'handle distance', (x) => x.toExponential(2), 'Largest distance of a handle vertex from its target', 'metric-handle'],
  ['unfolding_flipped_faces', 'flipped faces in M′', (x) => String(x), 'Faces of M′ turned over (0 for a valid unfolding)', 'metric-flipped'],
  ['gauss_curvature_max_abs', 'max |K|', (x) => x.toExponential(2), 'Largest |Gauss curvature| of a face (with the Gauss image)', 'metric-gauss'],
  ['rounds', 'rounds', (x) => String(x), 'Rounds of Algorithm 1 in the last solve', 'metric-rounds'],
  ['unknowns', 'unknowns', (x) => String(x), 'Scalar unknowns of the problem', 'metric-unknowns'],
];

export class QuadMeshControls {
  /**
   * @param {object} deps {state, quad (QuadMeshBuffers), send(command), toasts, errorSlots,
   *   changed() (colours or glue marks changed: redraw both views and the legend)}
   */
  constructor(deps) {
    Object.assign(this, deps);
    /** Gluing: null when off, else {on: 'mesh'|'unfolding', first: vertex|null}. */
    this.glueMode = null;
    this.glueOn = 'mesh';
    this._buildViewOptions();
    this._buildGluePanel();
    this._buildMetricsPanel();
    const st = this.state;
    st.on('scene', () => this._sceneChanged());
    st.on('metrics', () => this._renderMetrics());
    st.on('session', () => this._sceneChanged());
  }

  get model() {
    return (this.state.scene && this.state.scene.model) || {};
  }

  // ---- colour mode and the Gauss image ---------------------------------------------------------

  _buildViewOptions() {
    this.colorSelect = h('select', { class: 'input small', testid: 'quad-color-mode', 'aria-label': 'Colour by', title: 'Colour M and M′ by' },
      Object.entries(QUAD_COLOR_MODES).map(([value, m]) => h('option', { value, title: m.title }, m.label)));
    this.colorSelect.addEventListener('change', () => this.setColorMode(this.colorSelect.value));
    this.gaussInput = h('input', { type: 'checkbox', testid: 'gauss-image' });
    this.gaussInput.addEventListener('change', () => this._sendGaussImage(this.gaussInput.checked));
    this.viewOptions = [
      h('label', { class: 'chip', title: 'Colour M and M′ by: L-Err per edge, Gauss curvature K or mean curvature H per face' }, 'Colour ', this.colorSelect),
      h('label', { class: 'chip', title: 'Solve the Gauss image (vertex normals) for curvatures and rulings (set_params gauss_image)' }, this.gaussInput, 'Gauss image'),
    ];
  }

  /** 'length_error' | 'gauss' | 'mean'; K and H switch the Gauss image on when it is off. */
  setColorMode(mode) {
    this.colorSelect.value = mode;
    this.quad.setColorMode(mode);
    if (QUAD_COLOR_MODES[mode].needsCurvature && !this.model.gauss_image && this.state.role === 'edit') {
      this._sendGaussImage(true);
    }
    this.changed();
  }

  _sendGaussImage(on) {
    this.send(new SetParamsCommand('quad_mesh', { gauss_image: on }, { source: 'quad:gauss_image' }));
  }

  /** Legend text while K/H wait for the curvature. */
  get legendNote() {
    const info = this.quad.colorInfo;
    if (info.needsCurvature && !this.quad.hasCurvature) return this.model.gauss_image ? 'computing…' : 'Gauss image off';
    return null;
  }

  // ---- gluing ----------------------------------------------------------------------------------

  _buildGluePanel() {
    this.glueButton = h('button', { class: 'btn', testid: 'glue-mode', 'aria-pressed': 'false', title: 'Pick two boundary vertices (in M or M′) to glue them (G)', onclick: () => this.toggleGlueMode() }, 'Glue vertices (G)');
    this.glueOnSelect = h('select', { class: 'input small', testid: 'glue-on', title: 'Which mesh the picked pair is glued on' },
      h('option', { value: 'mesh' }, 'on M (3D)'), h('option', { value: 'unfolding' }, 'on M′ (unfolding)'));
    this.glueOnSelect.addEventListener('change', () => {
      this.glueOn = this.glueOnSelect.value;
      if (this.glueMode) this.glueMode.on = this.glueOn;
    });
    this.glueStatus = h('p', { class: 'muted small', testid: 'glue-status' }, '');
    this.glueList = h('ol', { class: 'glue-list', testid: 'glue-list' });
    this.glueCount = h('span', { class: 'muted small' }, '');
    this.gluePanel = h('section', { class: 'panel', testid: 'glue-panel', hidden: true },
      h('h3', {}, 'Gluing ', this.glueCount),
      h('div', { class: 'button-row' }, this.glueButton, this.glueOnSelect),
      this.glueStatus, this.errorSlots.slot('quad:glue'), this.glueList);
  }

  toggleGlueMode(on = !this.glueMode) {
    this.glueMode = on ? { on: this.glueOn, first: null } : null;
    this.glueButton.setAttribute('aria-pressed', String(!!on));
    this.glueButton.classList.toggle('active', !!on);
    this._renderGlueStatus();
    this.changed();
  }

  /** The first vertex picked in glue mode, or null. */
  get glueFirst() {
    return this.glueMode ? this.glueMode.first : null;
  }

  /**
   * A press on a vertex of M or M′ (target). In glue mode it is a pick (returns true: no drag):
   * boundary vertices only; the second pick sends the glue list with the pair appended and a solve.
   */
  pointDown(target) {
    if (!this.glueMode) return false;
    const v = target.vertex;
    if (!this.quad.isBoundary(v)) {
      this.toasts.showInfo(`Vertex ${v} is not on the boundary: glue boundary vertices (the cut edges).`);
      return true;
    }
    const g = this.glueMode;
    if (g.first === null || g.first === v) {
      g.first = g.first === v ? null : v;
      this._renderGlueStatus();
      this.changed();
      return true;
    }
    this.addPair(g.on, g.first, v);
    g.first = null;
    this._renderGlueStatus();
    this.changed();
    return true;
  }

  addPair(on, a, b) {
    let glue;
    try {
      glue = withGluePair(this.model.glue, on, a, b);
    } catch (e) {
      this.errorSlots.show('quad:glue', e.message);
      return null;
    }
    this.errorSlots.clear('quad:glue');
    const op = this.send(glueCommand(glue, { source: 'quad:glue' }));
    // Close the gap right away (an edit of its own; undo takes it back first).
    this.send(new SolveCommand(undefined, { source: 'quad:glue' }));
    return op;
  }

  removePair(group, index) {
    const glue = withoutGluePair(this.model.glue, group, index);
    this.send(glueCommand(glue, { source: 'quad:glue' }));
  }

  _renderGlueStatus() {
    const g = this.glueMode;
    if (!g) this.glueStatus.textContent = 'Gluing off. Glued pairs are drawn green in both views (numbered in M′).';
    else if (g.first === null) this.glueStatus.textContent = `Pick a boundary vertex (in M or M′) to glue on ${g.on === 'mesh' ? 'M' : 'M′'}.`;
    else this.glueStatus.textContent = `Vertex ${g.first} picked — pick its partner (click it again to drop it; Esc leaves).`;
  }

  _renderGlueList() {
    const pairs = gluePairList(this.model.glue);
    this.glueCount.textContent = `(${pairs.length} pair${pairs.length === 1 ? '' : 's'})`;
    clear(this.glueList);
    const editable = this.state.role === 'edit';
    for (const [k, p] of pairs.slice(0, PAIRS_LISTED).entries()) {
      const remove = h('button', { class: 'btn small', testid: 'glue-remove', title: `Unglue ${p.pair[0]} and ${p.pair[1]}`, disabled: !editable,
        onclick: () => this.removePair(p.group, p.index) }, '×');
      this.glueList.appendChild(h('li', { testid: 'glue-pair', dataset: { pair: `${p.pair[0]}-${p.pair[1]}`, on: p.on } },
        h('span', { class: 'num' }, `${k + 1}. ${p.pair[0]} ↔ ${p.pair[1]}`), h('span', { class: 'muted small' }, p.on === 'mesh' ? ' on M' : ' on M′'), remove));
    }
    if (pairs.length > PAIRS_LISTED) this.glueList.appendChild(h('li', { class: 'muted small' }, `… and ${pairs.length - PAIRS_LISTED} more`));
  }

  // ---- metrics -----------------------------------------------------------------------------------

  _buildMetricsPanel() {
    this.metricRows = new Map();
    const rows = METRICS.map(([key, label, , title, testid]) => {
      const value = h('td', { class: 'num', testid }, '–');
      const row = h('tr', { title }, h('th', {}, label), value);
      this.metricRows.set(key, { row, value });
      return row;
    });
    this.metricsSection = h('section', { class: 'subpanel', hidden: true, testid: 'quad-metrics' },
      h('h3', {}, 'Developability ', h('span', { class: 'muted small' }, '(M′ against M, as in Fig. 22)')),
      h('div', { class: 'quad-metrics-body' }, h('table', { class: 'metrics-table' }, h('tbody', {}, rows))));
  }

  _renderMetrics() {
    const m = this.state.metrics || {};
    for (const [key, , format] of METRICS) {
      const { row, value } = this.metricRows.get(key);
      const v = m[key];
      row.hidden = typeof v !== 'number';
      if (typeof v === 'number') value.textContent = format(v);
    }
  }

  // ---- state -------------------------------------------------------------------------------------

  _sceneChanged() {
    if (this.state.kind !== 'quad_mesh') return;
    this.gaussInput.checked = !!this.model.gauss_image;
    this.gaussInput.disabled = this.state.role !== 'edit';
    this.glueButton.disabled = this.state.role !== 'edit';
    this._renderGlueList();
    this._renderGlueStatus();
  }

  /** Shows or hides the quad-only controls. */
  setVisible(visible) {
    for (const el of this.viewOptions) el.hidden = !visible;
    this.gluePanel.hidden = !visible;
    this.metricsSection.hidden = !visible;
    if (!visible && this.glueMode) this.toggleGlueMode(false);
    if (visible) {
      this._sceneChanged();
      this._renderMetrics();
    }
  }
}
