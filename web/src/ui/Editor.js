// The editor page: layout, wiring of state ↔ client ↔ views ↔ panels, keyboard shortcuts.

import { h } from './dom.js';
import { CONICAL_COLOR_MODES, PATCH_TYPE_COLORS, StripBuffers } from '../geometry/StripBuffers.js';
import { MappingPlot } from './MappingPlot.js';
import { ParamsPanel } from './ParamsPanel.js';
import { CompositeBuffers, COMPOSITE_COLOR_MODES } from '../geometry/CompositeBuffers.js';
import { QuadMeshBuffers, isQuadMeshGeometry } from '../geometry/QuadMeshBuffers.js';
import { UnfoldingView } from '../view/UnfoldingView.js';
import { QuadMeshControls } from './QuadMeshControls.js';
import { ProtocolClient, defaultSocketUrl } from '../net/ProtocolClient.js';
import { listSessions } from '../net/api.js';
import { Viewport } from '../view/Viewport.js';
import { DevelopmentView } from '../view/DevelopmentView.js';
import { SolverPanel } from './SolverPanel.js';
import { FoldPanel } from './FoldPanel.js';
import { CreaseBoardPanel } from './CreaseBoardPanel.js';
import { drawingDiagonal } from '../geometry/creaseDrawing.js';
import { ResidualPlot } from './ResidualPlot.js';
import { HelpOverlay } from './HelpOverlay.js';
import { GroupRotateControls } from './GroupRotateControls.js';
import { CurvePointControls } from './CurvePointControls.js';
import { ErrorSlots, Toasts, describeError } from './Toast.js';
import { CreasePanel, ExportPanel, Legend, ParticipantsPanel, SelectionPanel, SharePanel, StatusBar } from './panels.js';
import { accessibility, displayName, rememberSessionTokens, sessionTokens, setAccessibility } from './preferences.js';
import {
  AddHandleCommand, DragCommand, DragEndCommand, PresenceCommand, RedoCommand, RemoveHandleCommand, ResetCommand, SetFixedCommand,
  SolveCommand, UndoCommand, sameTarget, targetOf,
} from '../commands/index.js';

const APPLY_TIMES_KEPT = 500;

const cssRgb = (c) => `rgb(${Math.round(c[0] * 255)}, ${Math.round(c[1] * 255)}, ${Math.round(c[2] * 255)})`;

export class Editor {
  /**
   * @param {HTMLElement} root
   * @param {object} options {state, session, token, socket?} (socket: see ProtocolClient.connect)
   */
  constructor(root, { state, session, token, socket = null }) {
    this.state = state;
    this.session = session;
    this.token = token;
    this.applyTimes = [];
    this.buffers = new StripBuffers();
    this.composite = new CompositeBuffers();
    this.quad = new QuadMeshBuffers();
    /** 'strip' | 'composite' | 'quad_mesh': the kind of the last geometry applied. */
    this.kind = 'strip';
    /** The strip kind shown: 'strip' | 'quasi_strip' | 'conical_strip'. */
    this.modelKind = 'strip';
    this.errorSlots = new ErrorSlots();
    state.name = displayName();
    const known = sessionTokens(session);
    state.setTokens({ edit: known.edit || null, view: known.view || null });

    this.client = new ProtocolClient({ url: defaultSocketUrl(), state });
    this._buildLayout(root);
    this._wire();
    // The editor starts as a strip's (this.kind); _setKind runs only when a geometry of another kind arrives.
    this.quadControls.setVisible(false);
    this._updateToolbar();
    this._bindKeyboard();
    this._applyAccessibility(accessibility());

    this.client.connect(session, token, state.name, socket);
    this._lookUpDemoTokens();
    window.addEventListener('online', () => this.client.reconnectNow());
  }

  // ---- layout ---------------------------------------------------------------------------------

  _buildLayout(root) {
    const st = this.state;
    const tb = (label, title, onclick, source, testid) => {
      const b = h('button', { class: 'btn tool', title, onclick, testid, 'aria-label': title }, label);
      if (source) b.dataset.source = source;
      return b;
    };
    this.undoButton = tb('↶ Undo', 'Undo (Ctrl+Z)', () => this.undo(), 'toolbar:undo', 'undo');
    this.redoButton = tb('↷ Redo', 'Redo (Ctrl+Shift+Z)', () => this.redo(), 'toolbar:redo', 'redo');
    this.solveButton = tb('Solve', 'Solve until every constraint is met, within 2 s (S)', () => this.solve(), 'toolbar:solve', 'solve');
    this.resetButton = tb('Reset', 'Back to the scene the session started with (undoable)', () => this.reset(), 'toolbar:reset', 'reset');
    this.a11yButton = h('button', { class: 'btn tool', title: 'Large text and high contrast', 'aria-pressed': 'false', testid: 'toggle-a11y',
      onclick: () => this._applyAccessibility(!document.documentElement.classList.contains('a11y'), true) }, 'Aa');
    this.helpButton = h('button', { class: 'btn tool', title: 'Keyboard shortcuts (?)', 'aria-label': 'Help', onclick: () => this.help.toggle() }, '?');
    this.sceneName = h('span', { class: 'scene-name' }, '');
    this.roleBadge = h('span', { class: 'badge role-badge', hidden: true }, '');

    const header = h('header', { class: 'topbar' },
      h('a', { class: 'brand', href: './', title: 'Back to the start page' }, 'devsurf'),
      this.sceneName, this.roleBadge,
      h('div', { class: 'toolbar' },
        h('div', { class: 'tool-group' }, this.undoButton, this.redoButton),
        h('div', { class: 'tool-group' }, this.solveButton, this.resetButton),
        h('div', { class: 'tool-group' }, this.a11yButton, this.helpButton)),
      h('div', { class: 'toolbar-errors' }, ['toolbar:undo', 'toolbar:redo', 'toolbar:solve', 'toolbar:reset'].map((s) => this.errorSlots.slot(s))));

    // 3D view with its overlays.
    this.viewportEl = h('div', { class: 'viewport', testid: 'viewport' });
    const toggle = (label, option, initial, key) => {
      const input = h('input', { type: 'checkbox', checked: initial });
      input.addEventListener('change', () => this.viewport.setOption(option, input.checked));
      return h('label', { class: 'chip', title: key ? `${label}` : label }, input, label);
    };
    this.colorMode = h('select', { class: 'input small', testid: 'color-mode', 'aria-label': 'Colour the faces by', title: 'Colour the faces by' },
      Object.entries(COMPOSITE_COLOR_MODES).map(([value, m]) => h('option', { value }, m.title)));
    this.colorMode.addEventListener('change', () => {
      this.composite.setColorMode(this.colorMode.value);
      this._updateLegend();
      this.viewport.requestRender();
    });
    this.conicalColorMode = h('select', { class: 'input small', testid: 'strip-color-mode', 'aria-label': 'Colour the patches by', title: 'Colour the patches by' },
      Object.entries(CONICAL_COLOR_MODES).map(([value, m]) => h('option', { value }, m.title)));
    this.conicalColorMode.addEventListener('change', () => {
      this.buffers.setColorMode(this.conicalColorMode.value);
      this._updateLegend();
      this.viewport.requestRender();
      this.development.render();
    });
    this.normalsToggle = toggle('Normals', 'normals', false);
    this.rulingsToggle = toggle('Rulings', 'rulings', true);
    this.stripOnlyOptions = [this.rulingsToggle, this.normalsToggle];
    // Shown when the strip approximates reference points (scene model.approximation).
    this.referenceToggle = toggle('Reference points', 'reference', true);
    this.referenceToggle.dataset.testid = 'reference-toggle';
    this.referenceToggle.title = 'The points the strip approximates, coloured by their distance to it: blue-green on it, red 3 % of their size away or more';
    this.referenceToggle.hidden = true;
    this.quadControls = new QuadMeshControls({
      state: st, quad: this.quad, send: (c) => this.send(c), toasts: { showInfo: (t) => this.toasts.showInfo(t) }, errorSlots: this.errorSlots,
      changed: () => this._quadChanged(),
    });
    this.conicalOnlyOptions = [h('label', { class: 'chip', title: 'Colour the patches by', hidden: true }, 'Colour ', this.conicalColorMode)];
    this.compositeOnlyOptions = [h('label', { class: 'chip', title: 'Colour the faces by', hidden: true }, 'Colour ', this.colorMode)];
    this.viewOptions = h('div', { class: 'view-options' },
      toggle('Surface', 'surface', true), ...this.stripOnlyOptions, this.referenceToggle, ...this.compositeOnlyOptions, ...this.conicalOnlyOptions, ...this.quadControls.viewOptions,
      this.polygonsToggle = toggle('Control polygons', 'polygons', true),
      h('button', { class: 'btn small', title: 'Fit the strip into the view (Space)', onclick: () => this.viewport.fit() }, 'Fit (Space)'));
    this.banner = h('div', { class: 'banner', hidden: true, role: 'status' });
    // quad_mesh sessions: the unfolding M′ beside the 3D view of M.
    this.unfoldingEl = h('div', { class: 'unfolding-pane', testid: 'unfolding-view', hidden: true });
    const viewportWrap = h('div', { class: 'viewport-wrap' }, this.viewportEl, this.unfoldingEl, this.viewOptions, this.banner,
      h('div', { class: 'viewport-errors' }, this.errorSlots.slot('viewport')),
      this.hint = h('div', { class: 'hint' }, 'drag points · F fix · H handle · S solve · ? help'));

    this.developmentEl = h('div', { class: 'development', testid: 'development-view' });
    this.plotEl = h('div', { class: 'plot' });
    this.mappingEl = h('div', { class: 'plot' });
    this.developmentTitle = h('span', { class: 'muted small' }, '(unrolled; double-click to refit)');
    this.residualSection = h('section', { class: 'subpanel' }, h('h3', {}, 'Residuals ', h('span', { class: 'muted small' }, '(weighted squared, per term)')), this.plotEl);
    this.mappingSection = h('section', { class: 'subpanel', hidden: true, testid: 'mapping-panel' },
      h('h3', {}, 'Mapping σ ', h('span', { class: 'muted small' }, '(rulings join C1(t) and C2(σ(t)))')), this.mappingEl);
    this.developmentSection = h('section', { class: 'subpanel' }, h('h3', {}, 'Development ', this.developmentTitle), this.developmentEl);
    const bottom = h('div', { class: 'bottom-panels' },
      this.developmentSection, this.quadControls.metricsSection, this.mappingSection, this.residualSection);

    this.sidebar = h('aside', { class: 'sidebar', testid: 'sidebar' });
    const main = h('main', { class: 'main' }, viewportWrap, bottom);
    this.root = h('div', { class: 'editor', testid: 'editor' }, header, main, this.sidebar);
    root.appendChild(this.root);

    // Views.
    this.viewport = new Viewport(this.viewportEl, {
      state: st, buffers: this.buffers, composite: this.composite, send: (c) => this.send(c), select: (t) => this.select(t),
      selectEdge: (e) => st.setSelectedEdge(e), quad: this.quad,
      pointDown: (t) => this.kind === 'quad_mesh' && this._quadPointDown(t),
      toggleGroup: (t) => this.kind === 'composite' && (st.toggleGroupMember(t), true),
    });
    this.unfolding = new UnfoldingView(this.unfoldingEl, {
      state: st, quad: this.quad, send: (c) => this.send(c), select: (t) => this.select(t),
      pointDown: (t) => this.quadControls.pointDown(t), glueFirst: () => this.quadControls.glueFirst,
    });
    this.legend = new Legend(viewportWrap);
    this.development = new DevelopmentView(this.developmentEl, { buffers: this.buffers, composite: this.composite });
    this.plot = new ResidualPlot(this.plotEl, { state: st });
    this.mappingPlot = new MappingPlot(this.mappingEl, { buffers: this.buffers });

    // Sidebar panels.
    this.selectionPanel = new SelectionPanel(this.sidebar, {
      state: st, pointOf: (t) => this.pointOf(t), errorSlots: this.errorSlots,
      toggleFixed: () => this.toggleFixed(), toggleHandle: () => this.toggleHandle(),
      moveTo: (t, position) => {
        // Typed coordinates: a drag to them and its release, one undo step like a mouse drag.
        this.send(new DragCommand(t, position, { source: 'selection:move' }));
        this.send(new DragEndCommand(t, undefined, { source: 'selection:move' }));
      },
      // A sheet drawn flat keeps its size as it folds: the grid follows the sheet, else the surface.
      designSize: () => drawingDiagonal(st.scene) ?? this.viewport.designSize(),
    });
    // Composites: insert or remove a control point of the selected S-edge point.
    this.curvePoints = new CurvePointControls(this.selectionPanel.root, {
      state: st, send: (c) => this.send(c), errorSlots: this.errorSlots,
    });
    // Composites: turn the group selection (Shift/Ctrl-click) about an axis (rotate_points).
    this.groupRotate = new GroupRotateControls(this.selectionPanel.root, {
      state: st, pointOf: (t) => this.pointOf(t), send: (c) => this.send(c), errorSlots: this.errorSlots,
      viewDirection: () => this.viewport.groupOverlay.viewDirection(), clearGroup: () => st.setGroup([]), before: this.selectionPanel.hint,
    });
    this.sidebar.appendChild(this.quadControls.gluePanel);
    // Composites made from a drawing: the crease-pattern board over the 3D view and bottom panels.
    this.creaseBoard = new CreaseBoardPanel({ host: main, sidebar: this.sidebar, state: st, send: (c) => this.send(c), errorSlots: this.errorSlots });
    this.creasePanel = new CreasePanel(this.sidebar, { state: st, composite: this.composite, send: (c) => this.send(c), errorSlots: this.errorSlots });
    this.foldPanel = new FoldPanel(this.sidebar, {
      state: st, send: (c) => this.send(c), errorSlots: this.errorSlots,
      // The largest along any crease (the server captures hinges at a crease's ends; a crease
      // folded one way at one end and the other at the other has a mean near 0).
      largestFoldDeg: () => Math.max(0, ...this.composite.edges.filter((e) => e.interior).map((e) => e.foldAngleMaxDeg || 0)),
    });
    this.paramsSection = h('section', { class: 'panel panel-gui', hidden: true });
    this.sidebar.appendChild(this.paramsSection);
    this.paramsPanel = new ParamsPanel(this.paramsSection, { state: st, send: (c) => this.send(c), errorSlots: this.errorSlots });
    const solverSection = h('section', { class: 'panel panel-gui' });
    this.solverSection = solverSection;
    this.sidebar.appendChild(solverSection);
    this.solverPanel = new SolverPanel(solverSection, { state: st, send: (c) => this.send(c), errorSlots: this.errorSlots });
    this.participants = new ParticipantsPanel(this.sidebar, { state: st, send: (c) => this.send(c) });
    this.share = new SharePanel(this.sidebar, { state: st });
    this.exportPanel = new ExportPanel(this.sidebar, {
      state: st, toasts: null, errorSlots: this.errorSlots, token: this.token, currentScene: () => this.currentScene(),
      send: (c) => this.send(c),
      designSize: () => drawingDiagonal(st.scene) ?? this.viewport.designSize(),
    });

    this.status = new StatusBar(this.root, { state: st, client: this.client, applyTimes: () => this.applyTimes });
    this.help = new HelpOverlay(this.root);
    this.toasts = new Toasts(document.body);
    this.exportPanel.toasts = this.toasts;
    // A word from a view (a press on a fixed point, say): shown as a toast.
    st.on('notice', (text) => this.toasts.showInfo(text));
  }

  // ---- wiring ---------------------------------------------------------------------------------

  _wire() {
    const st = this.state;
    st.on('geometry', ({ geometry, source }) => this._applyGeometry(geometry, source));
    st.on('session', (msg) => {
      this.sceneName.textContent = (msg.scene && msg.scene.name) || msg.session;
      document.title = `${(msg.scene && msg.scene.name) || msg.session} — devsurf`;
      this.roleBadge.textContent = msg.role === 'view' ? 'view only' : 'editing';
      this.roleBadge.hidden = false;
      this.roleBadge.classList.toggle('badge-view', msg.role === 'view');
      const tokens = msg.role === 'edit' ? { edit: this.token } : { view: this.token };
      tokens.opened = Date.now();  // listed under "Your sessions" on the start page
      if (msg.scene && msg.scene.name) tokens.name = msg.scene.name;
      st.setTokens(rememberSessionTokens(msg.session, tokens));
      this._updateToolbar();
      // A resync keeps the selection if the point still exists; tell the others again.
      if (st.selection && !this.pointOf(st.selection)) st.setSelection(null);
      if (st.group.length) st.setGroup(st.group.filter((t) => this.pointOf(t)));
      if (st.selection) this.send(new PresenceCommand(st.selection));
    });
    // The server tells editors the view link: remembered for "Your sessions" too.
    st.on('tokens', (t) => { if (t.view && st.session && sessionTokens(st.session).view !== t.view) rememberSessionTokens(st.session, { view: t.view }); });
    st.on('undo', () => this._updateToolbar());
    st.on('editable', () => {
      this._updateToolbar();
      this.viewport.requestRender();  // the group's turn centre is drawn only while editable
    });
    st.on('connection', ({ connection, detail }) => this._updateBanner(connection, detail));
    st.on('error', ({ message, command }) => this._showError(message, command));
    st.on('selection', (sel) => {
      this.viewport.requestRender();
      if (this.kind === 'quad_mesh') this.unfolding.render();
      if (st.connection === 'connected') this.send(new PresenceCommand(sel));
    });
    st.on('presence', () => this.viewport.requestRender());
    for (const ev of ['group', 'rotate-axis', 'rotate-centre']) st.on(ev, () => this.viewport.requestRender());
    st.on('edge-selection', () => this.viewport.updateComposite());
    st.on('solved', () => this.development.refit());
    // The scale bar speaks the design's units (the scene's `units`; absent means mm).
    st.on('scene', (scene) => {
      const units = (scene && scene.units) || 'mm';
      if (this.development.units === units) return;
      this.development.units = units;
      this.development.render();
    });
    st.on('scene', () => {
      const model = (st.scene && st.scene.model) || {};
      this.viewport.setReferencePoints(model.approximation ? model.approximation.points : null);
      this.referenceToggle.hidden = this.viewport.referenceCount === 0;
      this.viewport.requestRender();
      if (this.kind === 'quad_mesh') this.unfolding.render();
    });
  }

  /** Decode + buffer update + render, measured as 'iterate-apply' for iterates. */
  _applyGeometry(geometry, source) {
    const timed = source === 'iterate' && typeof performance !== 'undefined' && performance.mark;
    if (timed) performance.mark('iterate-apply-start');
    try {
      const kind = isQuadMeshGeometry(geometry) ? 'quad_mesh' : geometry && geometry.kind === 'composite' ? 'composite' : 'strip';
      if (kind === 'composite') this.composite.apply(geometry);
      else if (kind === 'quad_mesh') this.quad.apply(geometry);
      else {
        this.buffers.apply(geometry);
        this.viewport.setReferenceDistances(geometry.approximation_distances, geometry.approximation_tolerance);
      }
      if (kind !== this.kind) this._setKind(kind);
      if (kind === 'quad_mesh') this.quadControls.geometryApplied();
      if (kind === 'strip') this._setModelKind(this.buffers.modelKind);
      if (this.modelKind === 'quasi_strip') this.mappingPlot.update();
      if (kind === 'composite') {
        this.viewport.updateComposite();
        this.creasePanel.render();
      }
    } catch (e) {
      console.error('devsurf: cannot apply geometry', e);
      this.toasts.showError({ code: 'geometry', message: String(e.message || e) });
      return;
    }
    if (!this.viewport.hasFit) this.viewport.fit();
    // The fold slider moves the whole sheet: while this editor folds it (and shortly after), the
    // view follows when the sheet leaves it.
    else if (this.foldPanel && this.foldPanel.recentlyFolding() && this.viewport.surfaceOutsideView()) this.viewport.fit();
    this._updateLegend();
    this.selectionPanel.followDesignSize();
    this.viewport.renderNow();
    // Page-load measurements (bench/page_load.mjs, CONTRACT.md): the first surface drawn.
    if (!this.firstSurfaceMarked && this.viewport.renderer && typeof performance !== 'undefined' && performance.mark) {
      this.firstSurfaceMarked = true;
      performance.mark('devsurf:first-surface');
    }
    if (this.kind === 'quad_mesh') this.unfolding.render();
    else this.development.render();
    if (timed) {
      performance.mark('iterate-apply-end');
      const m = performance.measure('iterate-apply', 'iterate-apply-start', 'iterate-apply-end');
      const duration = m && typeof m.duration === 'number' ? m.duration : 0;
      this.applyTimes.push(duration);
      if (this.applyTimes.length > APPLY_TIMES_KEPT) this.applyTimes.splice(0, this.applyTimes.length - APPLY_TIMES_KEPT);
      performance.clearMarks('iterate-apply-start');
      performance.clearMarks('iterate-apply-end');
      if (performance.getEntriesByName('iterate-apply').length > 2 * APPLY_TIMES_KEPT) performance.clearMeasures('iterate-apply');
    }
  }

  _setKind(kind) {
    this.kind = kind;
    this.viewport.setKind(kind);
    this.development.setKind(kind);
    for (const el of this.stripOnlyOptions) el.hidden = kind !== 'strip';
    for (const el of this.compositeOnlyOptions) el.hidden = kind !== 'composite';
    if (kind !== 'strip') for (const el of this.conicalOnlyOptions) el.hidden = true;
    const quad = kind === 'quad_mesh';
    this.rulingsToggle.hidden = !(kind === 'strip' || quad);
    this.polygonsToggle.hidden = quad;
    this.quadControls.setVisible(quad);
    this.unfoldingEl.hidden = !quad;
    this.unfolding.setVisible(quad);
    this.developmentSection.hidden = quad;
    this.solverSection.hidden = quad;
    this.hint.textContent = quad ? 'drag vertices · F fix · H handle · G glue · S solve · ? help'
      : kind === 'composite' ? 'drag points · Shift+click group · R rotate · F fix · H handle · S solve · ? help' : 'drag points · F fix · H handle · S solve · ? help';
    this.root.dataset.kind = kind;
    // The 3D view just changed size (M′ takes half of it): fit in the new size.
    this.viewport.resize();
  }

  /** A press on a vertex of M in the 3D view: gluing picks, or no drag when M is held fixed. */
  _quadPointDown(t) {
    if (this.quadControls.pointDown(t)) return true;
    if (!this.quad.meshVariable) {
      this.select(t);
      this.toasts.showInfo('M is held fixed in this session (variable: unfolding): drag the vertices of M′.');
      return true;
    }
    return false;
  }

  /** Colour mode, glue marks, the spline or its display changed: legend, options and both views. */
  _quadChanged() {
    const spline = this.kind === 'quad_mesh' && this.quad.hasSpline;
    this.root.dataset.spline = String(spline);
    if (this.kind === 'quad_mesh') {
      // A spline session's control net shows with the control-polygon toggle.
      this.polygonsToggle.hidden = !spline;
      this.polygonsToggle.lastChild.textContent = spline ? 'Control net' : 'Control polygons';
      this.hint.textContent = `drag ${spline ? 'control points' : 'vertices'} · F fix · H handle · G glue · S solve · ? help`;
    }
    if (this.viewport.quadLayer) this.viewport.quadLayer.refresh();
    this._updateLegend();
    this.viewport.requestRender();
    this.unfolding.render();
  }

  /** Strip kinds: 'strip' | 'quasi_strip' | 'conical_strip' (panels, options, hints). */
  _setModelKind(modelKind) {
    if (modelKind === this.modelKind) return;
    this.modelKind = modelKind;
    const curves = modelKind === 'quasi_strip' || modelKind === 'conical_strip';
    this.root.dataset.modelKind = modelKind;
    this.mappingSection.hidden = modelKind !== 'quasi_strip';
    this.solverSection.hidden = curves;
    this.paramsSection.hidden = !curves;
    this.normalsToggle.hidden = curves;
    for (const el of this.conicalOnlyOptions) el.hidden = modelKind !== 'conical_strip';
    this.selectionPanel.editsConstraints = !curves;
    this.selectionPanel.render();
    this.residualSection.hidden = modelKind === 'conical_strip';
    this.hint.textContent = curves ? "drag the input curves' control points · parameters in the side panel · ? help" : 'drag points · F fix · H handle · S solve · ? help';
    this.developmentTitle.textContent = modelKind === 'conical_strip' ? '(unfolded patches; double-click to refit)' : '(unrolled; double-click to refit)';
    this.solveButton.textContent = 'Solve';
  }

  _updateLegend() {
    if (this.kind === 'strip' && this.buffers.categorical) {
      this.legend.showCategories([
        { label: 'triangular', color: cssRgb(PATCH_TYPE_COLORS[3]) },
        { label: 'quadrilateral', color: cssRgb(PATCH_TYPE_COLORS[4]) },
      ], 'patch type');
      return;
    }
    if (this.kind === 'strip' && this.buffers.modelKind === 'conical_strip') {
      this.legend.update(this.buffers.colorRange, this.buffers.warpMax, this.buffers.colorInfo);
      return;
    }
    if (this.kind === 'quad_mesh') {
      const info = this.quad.colorInfo;
      const note = this.quadControls.legendNote;
      this.legend.update(this.quad.colorRange * info.scale, this.quad.colorMax * info.scale,
        { title: note ? `${info.title} (${note})` : info.title, unit: info.unit ? ` ${info.unit}` : '', diverging: info.diverging });
      return;
    }
    if (this.kind === 'composite') {
      const info = this.composite.colorInfo;
      this.legend.update(this.composite.colorRange, this.composite.colorMax, { title: info.title, unit: info.unit });
    } else {
      this.legend.update(this.buffers.colorRange, this.buffers.warpMax);
    }
  }

  /** [x, y, z] of a point target of the shown model, or null. */
  pointOf(t) {
    return this.viewport.activeBuffers().pointOf(targetOf(t));
  }

  _showError(message, command) {
    const context = command ? command.name : null;
    // A refusal shown beside the control that sent it is not said again in a toast (a tryout's
    // refused crease was reported twice, on the crease board and in a corner); one whose control
    // is out of sight (a collapsed panel, a keyboard shortcut) still gets the toast.
    if (command && command.source && this.errorSlots.show(command.source, describeError(message))
        && this.errorSlots.isShown(command.source)) return;
    this.toasts.showError(message, context);
  }

  _updateToolbar() {
    const st = this.state;
    const edit = st.canEdit;
    this.undoButton.disabled = !edit || !(st.undo && st.undo.available > 0);
    this.redoButton.disabled = !edit || !(st.undo && st.undo.redo_available > 0);
    this.solveButton.disabled = !edit;
    this.resetButton.disabled = !edit;
    this.undoButton.title = `Undo (Ctrl+Z) — ${st.undo ? st.undo.available : 0} step(s)`;
    this.redoButton.title = `Redo (Ctrl+Shift+Z) — ${st.undo ? st.undo.redo_available : 0} step(s)`;
  }

  _updateBanner(connection, detail) {
    const b = this.banner;
    b.replaceChildren();
    if (connection === 'reconnecting') {
      const text = detail && detail.moving ? 'The session is moving to another server: reconnecting… '
        : 'Connection lost: reconnecting… ';
      b.append(text, h('button', { class: 'btn small', onclick: () => this.client.reconnectNow() }, 'Retry now'));
      b.hidden = false;
    } else if (connection === 'offline') {
      const reason = (detail && detail.reason) || 'Disconnected from the server.';
      b.append(`${reason} `, h('a', { href: './', class: 'btn small' }, 'Start page'));
      b.hidden = false;
    } else if (connection === 'connecting') {
      b.append('Connecting…');
      b.hidden = false;
    } else {
      b.hidden = true;
    }
  }

  async _lookUpDemoTokens() {
    // Demo sessions publish both tokens: complete the share links.
    try {
      const sessions = await listSessions();
      const s = sessions.find((x) => x.id === this.session);
      if (s) this.state.setTokens(rememberSessionTokens(s.id, { edit: s.edit_token, view: s.view_token }));
    } catch {
      /* the links we know stay */
    }
  }

  _applyAccessibility(on, store = false) {
    document.documentElement.classList.toggle('a11y', on);
    this.a11yButton.setAttribute('aria-pressed', String(on));
    if (store) setAccessibility(on);
    this.viewport.setLargePoints(on);
    this.development.highContrast = on;
    this.development.render();
    this.plot.setLarge(on);
    this.mappingPlot.setLarge(on);
    // Layout sizes change with the font size.
    requestAnimationFrame(() => {
      this.viewport.resize();
      this.development.resize();
    });
  }

  // ---- actions --------------------------------------------------------------------------------

  send(command) {
    return this.client.send(command);
  }

  /** Selects one point (or none): a plain click, Esc; the group selection is cleared. */
  select(target) {
    this.state.setGroup([]);
    this.state.setSelection(target);
  }

  solve(iterations = undefined) {
    this.send(new SolveCommand(iterations, { source: 'toolbar:solve' }));
  }

  undo() {
    this.send(new UndoCommand({ source: 'toolbar:undo' }));
  }

  redo() {
    this.send(new RedoCommand({ source: 'toolbar:redo' }));
  }

  reset() {
    this.send(new ResetCommand({ source: 'toolbar:reset' }));
  }

  _requireSelection() {
    if (this.modelKind === 'quasi_strip' || this.modelKind === 'conical_strip') {
      this.toasts.showInfo("This strip keeps its input curves: drag their control points; there are no fixed points or handles.");
      return null;
    }
    const sel = this.state.selection;
    if (!sel) this.toasts.showInfo('Select a control point first (click it in the 3D view).');
    return sel;
  }

  toggleFixed() {
    const sel = this._requireSelection();
    if (!sel) return;
    const fixed = this.state.isFixed(sel);
    this.send(new SetFixedCommand(sel, !fixed, { source: 'selection:fix' }));
  }

  toggleHandle() {
    const sel = this._requireSelection();
    if (!sel) return;
    const has = this.state.constraints.handles.some((x) => sameTarget(x, sel));
    if (has) {
      this.send(new RemoveHandleCommand(sel, { source: 'selection:handle' }));
    } else {
      const p = this.pointOf(sel);
      if (p) this.send(new AddHandleCommand(sel, p, undefined, { source: 'selection:handle' }));
    }
  }

  /** The scene as currently shown: the session's scene with the latest control points. */
  currentScene() {
    const st = this.state;
    if (!st.scene) return null;
    const scene = JSON.parse(JSON.stringify(st.scene));
    const model = scene.model || {};
    const round = (p) => p.map((v) => Number(v.toPrecision(7)));
    // The fold slider's amount as the session is at it (its metrics while it folds; the scene's
    // own value lags behind a slider gesture): a file saved folded at 100 % reopens at 100 %.
    if (model.kind === 'composite' && model.fold_angles && st.metrics && typeof st.metrics.fold_amount === 'number') {
      model.fold_amount = st.metrics.fold_amount;
    }
    if (model.kind === 'composite' && this.composite.hasData) {
      if (Array.isArray(model.vertices)) model.vertices = model.vertices.map((v, i) => round(this.composite.pointOf({ vertex: i }) || v));
      for (const [e, edge] of (model.edges || []).entries()) {
        if (Array.isArray(edge.points)) edge.points = edge.points.map((p, k) => round(this.composite.pointOf({ edge: e, index: k + 1 }) || p));
      }
    }
    if (model.kind === 'quad_mesh' && this.quad.hasData) {
      const V = this.quad.vertexCount;
      const c = model.control;
      if (c && Array.isArray(c.points) && c.points.length === this.quad.spline.controlCount) {
        c.points = c.points.map((p, i) => round(this.quad.pointOf({ vertex: i, on: 'control' })));
      }
      const mesh = model.mesh || {}, unfolding = model.unfolding || {};
      if (Array.isArray(mesh.vertices) && mesh.vertices.length === V) mesh.vertices = mesh.vertices.map((v, i) => round(this.quad.pointOf({ vertex: i })));
      if (Array.isArray(unfolding.vertices) && unfolding.vertices.length === V) {
        unfolding.vertices = unfolding.vertices.map((v, i) => round(this.quad.pointOf({ vertex: i, on: 'unfolding' })).slice(0, v.length));
      }
    }
    for (const c of this.buffers.curveNames) {
      const n = this.buffers.count(c);
      if (model[c] && model[c].points && model[c].points.length === n) {
        model[c].points = Array.from({ length: n }, (_, i) => this.buffers.point(c, i).map((v) => Number(v.toPrecision(7))));
      }
    }
    // The scene's spelling: a quad_mesh writes a fixed vertex of M as its index.
    model.fixed = model.kind === 'quad_mesh' ? st.constraints.fixed.map((f) => (f.on ? f : f.vertex)) : st.constraints.fixed;
    model.handles = st.constraints.handles;
    if (!model.handles.length) delete model.handles;
    if (!model.fixed.length) delete model.fixed;
    return scene;
  }

  controlPointScreenPosition(curve, index) {
    return this.viewport.controlPointScreenPosition(curve, index);
  }

  pointScreenPosition(target) {
    return this.viewport.pointScreenPosition(target);
  }

  edgeScreenPosition(edge) {
    return this.viewport.edgeScreenPosition(edge);
  }

  // ---- keyboard -------------------------------------------------------------------------------

  _bindKeyboard() {
    window.addEventListener('keydown', (e) => {
      if (this.creaseBoard.handleKey(e)) return;
      const t = e.target;
      const typing = t && (t.tagName === 'INPUT' || t.tagName === 'TEXTAREA' || t.tagName === 'SELECT' || t.isContentEditable);
      if (e.key === 'Escape') {
        if (this.help.visible) this.help.hide();
        else if (!typing && this.quadControls.glueMode) this.quadControls.toggleGlueMode(false);
        else if (!typing) this.select(null);
        return;
      }
      if (typing) return;
      const ctrl = e.ctrlKey || e.metaKey;
      const key = e.key.length === 1 ? e.key.toLowerCase() : e.key;
      if (ctrl && key === 'z') {
        e.preventDefault();
        if (e.shiftKey) this.redo();
        else this.undo();
        return;
      }
      if (ctrl && key === 'y') {
        e.preventDefault();
        this.redo();
        return;
      }
      if (ctrl && key === 's') {
        e.preventDefault();
        this.exportPanel.saveScene(() => this.currentScene());
        return;
      }
      if (ctrl || e.altKey) return;
      if (e.key === '?') {
        e.preventDefault();
        this.help.toggle();
      } else if (key === 'f') {
        e.preventDefault();
        this.toggleFixed();
      } else if (key === 'h') {
        e.preventDefault();
        this.toggleHandle();
      } else if (key === 'g' && this.kind === 'quad_mesh') {
        e.preventDefault();
        this.quadControls.toggleGlueMode();
      } else if (key === 'r' && this.groupRotate.visible) {
        e.preventDefault();
        this.groupRotate.rotate(e.shiftKey ? -1 : 1);
      } else if (key === 's') {
        e.preventDefault();
        this.solve();
      } else if (e.key === ' ' || e.code === 'Space') {
        e.preventDefault();
        this.viewport.fit();
      }
    });
  }
}
