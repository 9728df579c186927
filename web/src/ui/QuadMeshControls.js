// The controls of a quad_mesh session (Jiang et al. 2020): the colour mode (L-Err per edge, K, H,
// and K·d² of the limit surface for spline sessions) with the Gauss-image switch, which surface a
// spline session shows (the limit surface M^∞ or the refined mesh S^k(M)), gluing (a mode that
// picks two boundary vertices in either view and sends set_params glue with the pair appended,
// then a solve; the list of glued pairs with a remove button each) and the metrics of Fig. 22
// (L-Err, A-Err in %, glue gap, …) with, for a spline, M^∞'s scale-free curvature and normal
// jumps from the streamed geometry (live with every iterate).

import { NEGLIGIBLE_MAGNITUDE, h, clear, formatExponential, formatSignificant } from './dom.js';
import { QUAD_COLOR_MODES, SPLINE_DISPLAYS } from '../geometry/QuadMeshBuffers.js';
import { SetParamsCommand } from '../commands/SetParamsCommand.js';
import { SolveCommand } from '../commands/SolveCommand.js';
import { glueCommand, gluePairList, withGluePair, withoutGluePair } from '../commands/glue.js';

const PAIRS_LISTED = 300;

/** A fraction as a percentage with 3 significant digits ('0.0931 %'; tiny values exponential). */
export function percent(x) {
  if (typeof x !== 'number' || !Number.isFinite(x)) return '–';
  if (Math.abs(x) < NEGLIGIBLE_MAGNITUDE) return '0 %';
  const p = 100 * x;
  return `${Math.abs(p) < 1e-3 ? formatExponential(p, 2) : formatSignificant(p, 3)} %`;
}

/** A number with 3 significant digits (tiny and huge ones exponential). */
export function significant(x) {
  if (typeof x !== 'number' || !Number.isFinite(x)) return '–';
  const a = Math.abs(x);
  return a < 1e-3 || a >= 1e5 ? formatExponential(x, 2) : formatSignificant(x, 3);
}

/**
 * Rows of a spline surface (issue 14), from the geometry's `spline` (SplineBuffers) and the
 * session's metrics (`…_initial`: the values at the scene's control points, i.e. before the last
 * edit was solved): [key, label, format, title, testid]. `format(spline, metrics)` returns the
 * text, or null to hide the row.
 */
const SPLINE_ROWS = [
  ['gauss_max', 'limit surface: max |K|·d²', (s, m) => withBefore(s.gaussMaxScaled, m.spline_gauss_max_scaled_initial),
    'Largest |Gauss curvature| × diameter² of the limit surface over its samples (0 where developable); in brackets the value before the last edit was solved', 'metric-spline-gauss-max'],
  ['gauss_mean', 'limit surface: mean |K|·d²', (s, m) => withBefore(s.gaussMeanScaled, m.spline_gauss_mean_scaled_initial),
    'Area-weighted mean of |K| × diameter² over the limit surface; in brackets the value before the last edit was solved', 'metric-spline-gauss-mean'],
  ['normal_jump', 'normal jump', (s) => (s.sharedSides > 0 ? `${significant(s.normalJumpMaxDeg)}° (${s.sharedSides} shared side${s.sharedSides === 1 ? '' : 's'})` : null),
    'Largest angle between the normals of two patches along a side they share (0° = tangent-continuous)', 'metric-spline-normal-jump'],
  ['rulings', 'rulings of the limit surface', (s) => String(s.rulingCount),
    'Rulings traced on the limit surface where it is developable and curved', 'metric-spline-rulings'],
  ['net', 'control net', (s) => `${s.controlCount} points · ${s.patchCount} patch${s.patchCount === 1 ? '' : 'es'} · k = ${s.rounds}`,
    'Control points M, bicubic patches, and the subdivision rounds k of the refined mesh Sᵏ(M)', 'metric-control-net'],
];

function withBefore(now, before) {
  const text = significant(now);
  return typeof before === 'number' && Number.isFinite(before) ? `${text} (before ${significant(before)})` : text;
}

/** Metrics shown for a quad mesh: [metric, label, format, title]. */
const METRICS = [
  ['length_error', 'L-Err', percent, 'Edge length error ‖L′ − L‖/‖L‖ over all edges (Jiang et al. Fig. 22)', 'metric-length-error'],
  ['edge_length_error_max', 'max edge error', percent, 'Largest |l′ − l|/l of one edge: a short edge stretched, which L-Err hides among long ones', 'metric-edge-length-error'],
  ['area_error', 'A-Err', percent, 'Face area error ‖A′ − A‖/‖A‖ over the faces (Fig. 22)', 'metric-area-error'],
  ['glue_gap_max', 'glue gap', (x) => formatExponential(x, 2), 'Largest distance of a glued pair ÷ the bounding-box diagonal of M', 'metric-glue-gap'],
  ['isometry_residual_max', 'isometry residual', (x) => formatExponential(x, 2), 'Largest residual of the checkerboard isometry (eq. 1)', 'metric-isometry'],
  ['handle_distance_max', 'handle distance', (x) => formatExponential(x, 2), 'Largest distance of a handle vertex from its target', 'metric-handle'],
  ['unfolding_flipped_faces', 'flipped faces in M′', (x) => String(x), 'Faces of M′ turned over (0 for a valid unfolding)', 'metric-flipped'],
  ['gauss_curvature_max_abs', 'max |K|', (x) => formatExponential(x, 2), 'Largest |Gauss curvature| of a face (with the Gauss image)', 'metric-gauss'],
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
    /** Whether the last geometry had a spline (the spline controls are shown). */
    this.spline = false;
    /** The colour mode was picked by the user (a spline session then keeps it). */
    this._colorPicked = false;
    this._buildViewOptions();
    this._buildGluePanel();
    this._buildMetricsPanel();
    const st = this.state;
    st.on('scene', () => this._sceneChanged());
    st.on('metrics', () => this._renderMetrics());
    st.on('session', () => this._sceneChanged());
    st.on('editable', () => this._sceneChanged());
    // A Gauss-image edit refused (by the server, or not sent while offline): the box shows the
    // scene's value again, not the click that did not happen.
    st.on('error', ({ command }) => {
      if (command && command.source === 'quad:gauss_image' && this.model) this.gaussInput.checked = !!this.model.gauss_image;
    });
  }

  get model() {
    return (this.state.scene && this.state.scene.model) || {};
  }

  // ---- colour mode and the Gauss image ---------------------------------------------------------

  _buildViewOptions() {
    this.colorSelect = h('select', { class: 'input small', testid: 'quad-color-mode', 'aria-label': 'Colour by', title: 'Colour M and M′ by' },
      Object.entries(QUAD_COLOR_MODES).map(([value, m]) => h('option', { value, title: m.title }, m.label)));
    this.colorSelect.addEventListener('change', () => {
      this._colorPicked = true;
      this.setColorMode(this.colorSelect.value);
    });
    this.splineColorOption = this.colorSelect.querySelector('option[value="spline_gauss"]');
    this.splineColorOption.hidden = true;
    this.gaussInput = h('input', { type: 'checkbox', testid: 'gauss-image' });
    this.gaussInput.addEventListener('change', () => this._sendGaussImage(this.gaussInput.checked));
    this.displaySelect = h('select', { class: 'input small', testid: 'quad-display', 'aria-label': 'Show', title: 'The surface shown in the 3D view' },
      Object.entries(SPLINE_DISPLAYS).map(([value, d]) => h('option', { value, title: d.title }, d.label)));
    this.displaySelect.addEventListener('change', () => this.setDisplay(this.displaySelect.value));
    this.displayChip = h('label', { class: 'chip', title: 'Show the limit surface M^∞ (the spline itself) or the refined mesh Sᵏ(M) the solver optimizes', hidden: true },
      'Show ', this.displaySelect);
    this.viewOptions = [
      h('label', { class: 'chip', title: 'Colour M and M′ by: L-Err per edge, Gauss curvature K or mean curvature H per face; a spline surface by its K·d²' }, 'Colour ', this.colorSelect),
      h('label', { class: 'chip', title: 'Solve the Gauss image (vertex normals) for curvatures and rulings (set_params gauss_image)' }, this.gaussInput, 'Gauss image'),
      this.displayChip,
    ];
  }

  /** 'limit' | 'refined': the surface a spline session shows in the 3D view. */
  setDisplay(display) {
    this.displaySelect.value = display;
    if (this.quad.setDisplay(display)) this.changed();
  }

  /** 'length_error' | 'gauss' | 'mean'; K and H switch the Gauss image on when it is off. */
  setColorMode(mode) {
    this.colorSelect.value = mode;
    this.quad.setColorMode(mode);
    // Not again when the box was just ticked (its set_params in flight): one edit, one undo step.
    if (QUAD_COLOR_MODES[mode].needsCurvature && !this.model.gauss_image && !this.gaussInput.checked && this.state.canEdit) {
      this.gaussInput.checked = true;  // what is on its way; the scene's value replaces it
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
    if (target.on === 'control') {
      this.toasts.showInfo('Control points are not glued: show the refined mesh Sᵏ(M) and pick its boundary vertices, or pick them in M′.');
      return true;
    }
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
    const editable = this.state.canEdit;
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
    this.splineRows = new Map();
    const row = (map, [key, label, , title, testid]) => {
      const value = h('td', { class: 'num', testid }, '–');
      const tr = h('tr', { title }, h('th', {}, label), value);
      map.set(key, { row: tr, value });
      return tr;
    };
    const rows = [...SPLINE_ROWS.map((r) => row(this.splineRows, r)), ...METRICS.map((r) => row(this.metricRows, r))];
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
    this._renderSplineMetrics();
  }

  _renderSplineMetrics() {
    const s = this.quad.spline;
    const m = this.state.metrics || {};
    for (const [key, , format] of SPLINE_ROWS) {
      const { row, value } = this.splineRows.get(key);
      const text = s.present ? format(s, m) : null;
      row.hidden = text === null;
      if (text !== null) value.textContent = text;
    }
  }

  /**
   * After every geometry applied: the spline's numbers, and the spline controls when a spline
   * appears (a spline session opens on its limit surface coloured by K·d², unless the user picked
   * a colour mode) or goes.
   */
  geometryApplied() {
    const spline = this.quad.hasSpline;
    if (spline !== this.spline) {
      this.spline = spline;
      this.displayChip.hidden = !spline || !this.visible;
      this.splineColorOption.hidden = !spline;
      if (spline && !this._colorPicked) this.quad.setColorMode('spline_gauss');
      this.colorSelect.value = this.quad.colorMode;
      this.displaySelect.value = this.quad.display;
      this.changed();
    }
    this._renderSplineMetrics();
  }

  // ---- state -------------------------------------------------------------------------------------

  _sceneChanged() {
    if (this.state.kind !== 'quad_mesh') return;
    this.gaussInput.checked = !!this.model.gauss_image;
    this.gaussInput.disabled = !this.state.canEdit;
    this.glueButton.disabled = !this.state.canEdit;
    this._renderGlueList();
    this._renderGlueStatus();
  }

  /** Shows or hides the quad-only controls. */
  setVisible(visible) {
    this.visible = visible;
    for (const el of this.viewOptions) el.hidden = !visible;
    this.displayChip.hidden = !visible || !this.spline;
    this.gluePanel.hidden = !visible;
    this.metricsSection.hidden = !visible;
    if (!visible && this.glueMode) this.toggleGlueMode(false);
    if (visible) {
      this._sceneChanged();
      this._renderMetrics();
    }
  }
}
