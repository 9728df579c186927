// The editor's smaller panels: status line, participants, share links, export, selection, legend.

import { h, clear, copyText, download, formatExponential, formatFixed, formatNumber, formatSignificant, slug } from './dom.js';
import { sameTarget, targetLabel } from '../commands/Command.js';
import { CREASE_KINDS, SetCreaseCommand } from '../commands/SetCreaseCommand.js';
import { MergeFacesCommand, RelabelEdgeCommand, RemoveVertexCommand, SplitAlongRulingCommand, SplitEdgeCommand, SplitFaceCommand } from '../commands/LabelledMeshCommands.js';
import { mergeProblem, relabelGroup, relabelProblem, splitCandidate } from '../geometry/labelledMesh.js';
import { PresenceCommand } from '../commands/PresenceCommand.js';
import { SetUnitsCommand, UNITS } from '../commands/SetUnitsCommand.js';
import { DRAG_CONSTRAINTS, defaultGridStep } from '../view/dragConstraint.js';
import { exportSession } from '../net/api.js';
import { cutAlongSeams, exportFormats } from './exportFormats.js';
import { cssDivergingGradient, cssGradient } from '../geometry/colormap.js';
import { displayName, setDisplayName } from './preferences.js';
import { describeEdit } from './activityText.js';

/** Status line: connection, iteration, max warp, time per iteration, last solve, seq. */
export class StatusBar {
  constructor(parent, { state, client, applyTimes }) {
    this.state = state;
    this.client = client;
    this.applyTimes = applyTimes;
    this.dot = h('span', { class: 'conn-dot', 'aria-hidden': 'true' });
    this.connection = h('span', { testid: 'status-connection' }, state.connection);
    this.retry = h('span', { class: 'muted' });
    this.iteration = h('span', { testid: 'status-iteration', class: 'num' }, '0');
    this.warp = h('span', { testid: 'status-warp', class: 'num' }, '–');
    this.warpMean = h('span', { class: 'num' }, '–');
    this.flatness = h('span', { class: 'num', testid: 'status-flatness' }, '–');
    this.flatnessItem = h('span', { class: 'status-item', title: 'Largest face flatness δ (Tang et al. Fig. 17; 0 = every sampled quad planar)', hidden: true }, 'max δ ', this.flatness);
    this.patches = h('span', { class: 'num', testid: 'status-patches' }, '–');
    this.normalJump = h('span', { class: 'num', testid: 'status-normal-jump' }, '–');
    this.patchesItem = h('span', { class: 'status-item', title: 'Conical patches: triangular (n3) and quadrilateral (n4), Chu et al.', hidden: true }, 'patches ', this.patches);
    this.normalJumpItem = h('span', { class: 'status-item', title: 'Largest angle between the normals of neighbouring patches (0° = G1)', hidden: true }, 'max normal jump ', this.normalJump, '°');
    this.lengthError = h('span', { class: 'num', testid: 'status-length-error' }, '–');
    this.lengthErrorItem = h('span', { class: 'status-item', title: 'L-Err: edge length error of M′ against M, ‖L′ − L‖/‖L‖ (Jiang et al. Fig. 22)', hidden: true }, 'L-Err ', this.lengthError, ' %');
    this.fit = h('span', { class: 'num', testid: 'status-fit' }, '–');
    this.fitItem = h('span', { class: 'status-item', title: 'A fitted strip: RMS and largest distance of its reference points from the surface, in % of their bounding-box diagonal (Tang et al. §4.2), and the share within 1 %', hidden: true }, 'fit ', this.fit);
    this.time = h('span', { class: 'num' }, '–');
    this.apply = h('span', { class: 'num' }, '–');
    this.solved = h('span', { class: 'muted', testid: 'status-solved' }, '');
    this.quality = h('span', { class: 'status-item quality', testid: 'status-quality', hidden: true }, '');
    this.seq = h('span', { class: 'num' }, '0');
    this.root = h('footer', { class: 'statusbar', role: 'status', 'aria-live': 'polite' },
      h('span', { class: 'status-item conn', title: 'Connection to the daemon' }, this.dot, this.connection, this.retry),
      // The verdicts first: on a narrow window the line is cut at its end, where the timings are
      // (a tryout at 1280 px read "solved: ran its 1000 iteratio").
      this.quality, this.solved,
      h('span', { class: 'status-item', title: 'Iteration number of the last solver iterate' }, 'iteration ', this.iteration),
      this.warpItem = h('span', { class: 'status-item', title: 'Largest warp angle over the strips and strip-like faces (0° = developable)' }, 'max warp ', this.warp, '°'),
      this.warpMeanItem = h('span', { class: 'status-item', title: 'Mean warp angle' }, 'mean ', this.warpMean, '°'),
      this.flatnessItem, this.patchesItem, this.normalJumpItem, this.lengthErrorItem, this.fitItem,
      h('span', { class: 'status-item', title: 'Server time of the last iteration' }, 'time/iter ', this.time, ' ms'),
      h('span', { class: 'status-item', title: 'Client time to decode, update and draw an iterate' }, 'draw ', this.apply, ' ms'),
      h('span', { class: 'status-item', title: 'Last edit sequence number seen' }, 'seq ', this.seq));
    parent.appendChild(this.root);
    state.on('connection', () => this.render());
    state.on('metrics', () => this.render());
    state.on('iterate', () => this.render());
    state.on('solved', () => this.render());
    state.on('session', () => this.render());
    state.on('ack', () => this.render());
    setInterval(() => this._renderRetry(), 500);
    this.render();
  }

  _renderRetry() {
    const at = this.client && this.client.nextRetryAt;
    if (this.state.connection === 'reconnecting' && at) {
      this.retry.textContent = ` (retry in ${Math.max(0, Math.ceil((at - Date.now()) / 1000))} s)`;
    } else {
      this.retry.textContent = '';
    }
  }

  render() {
    const st = this.state;
    this.connection.textContent = st.connection;
    this.dot.dataset.state = st.connection;
    this._renderRetry();
    const m = st.metrics || {};
    if (typeof m.warp_angle_max_deg === 'number') this.warp.textContent = formatNumber(m.warp_angle_max_deg);
    if (typeof m.warp_angle_mean_deg === 'number') this.warpMean.textContent = formatNumber(m.warp_angle_mean_deg);
    // quad meshes (Jiang et al.): L-Err instead of a warp angle.
    const quad = typeof m.length_error === 'number' && typeof m.warp_angle_max_deg !== 'number';
    this.lengthErrorItem.hidden = !quad;
    if (quad) this.lengthError.textContent = formatSignificant(100 * m.length_error, 3);
    const fitted = typeof m.approximation_distance_rms_relative === 'number';
    this.fitItem.hidden = !fitted;
    if (fitted) {
      const pct = (x) => formatSignificant(100 * x, 2);
      this.fit.textContent = `RMS ${pct(m.approximation_distance_rms_relative)} % · max ${pct(m.approximation_distance_max_relative)} % · ${pct(m.approximation_coverage)} % covered`;
    }
    this.flatnessItem.hidden = typeof m.face_flatness_max !== 'number';
    if (!this.flatnessItem.hidden) this.flatness.textContent = formatExponential(m.face_flatness_max, 1);
    // Conical strips (Chu et al.) report patches and normal jumps instead of a warp angle.
    const conical = typeof m.n3 === 'number' && typeof m.warp_angle_max_deg !== 'number';
    this.patchesItem.hidden = !conical;
    this.normalJumpItem.hidden = !conical;
    this.warpItem.hidden = conical || quad;
    this.warpMeanItem.hidden = conical || quad;
    if (conical) {
      this.patches.textContent = `${m.n3 + m.n4} (▲ ${m.n3} · ▮ ${m.n4})`;
      const jump = ((m.normal_jump_max_rad || 0) * 180) / Math.PI;
      this.normalJump.textContent = Math.abs(jump) < 0.01 ? formatExponential(jump, 1) : formatNumber(jump);
    }
    if (st.lastIterate) {
      this.iteration.textContent = String(st.lastIterate.iteration);
      if (typeof st.lastIterate.time_ms === 'number') this.time.textContent = st.lastIterate.time_ms.toFixed(2);
    }
    const times = this.applyTimes();
    if (times.length) {
      const recent = times.slice(-20);
      this.apply.textContent = (recent.reduce((a, b) => a + b, 0) / recent.length).toFixed(1);
    }
    this.seq.textContent = String(st.seq);
    if (st.lastSolved) this.solved.textContent = solvedText(st.lastSolved);
    const q = st.quality;
    this.quality.hidden = !q || !q.checks || q.checks.length === 0;
    if (q && q.checks && q.checks.length) {
      // The quality thresholds of the kind (server's verdict): ✓ when all are met, else the first miss.
      const miss = q.checks.find((c) => !c.ok);
      this.quality.textContent = q.met ? '✓ quality met' : `✗ ${miss.metric.replace(/_/g, ' ')} ${formatNumber(miss.value)} (limit ${formatNumber(miss.limit)})`;
      this.quality.classList.toggle('quality-miss', !q.met);
      this.quality.title = q.checks.map((c) => `${c.ok ? '✓' : '✗'} ${c.metric} = ${formatNumber(c.value)} (limit ${formatNumber(c.limit)})`).join('\n');
    }
  }
}

/**
 * The last solve in words: how it ended (the report's termination reason) and after how many
 * iterations. A release that used all its iterations is not a failure: the quality verdict beside
 * it says whether the design is good.
 */
export function solvedText({ reason, iterations }) {
  const n = `${iterations} iteration${iterations === 1 ? '' : 's'}`;
  switch (reason) {
    case 'max_iterations': return `solved: ran its ${n}`;
    case 'residual_tolerance':
    case 'relative_change':
    case 'hard_tolerance':
    case 'hard_plateau':
    case 'completed': return `solved: converged after ${n}`;
    case 'time_budget': return `solved: stopped at its time budget after ${n}`;
    case 'stalled': return `solved: stalled after ${n} (no step was accepted)`;
    case 'diverged': return `solve diverged after ${n}; the last good state is kept`;
    case 'aborted': return `solve interrupted after ${n}`;
    case 'identity_fallback': return `solved: kept the identity mapping (${n})`;
    default: return `solved: ${String(reason || '').replace(/_/g, ' ')} after ${n}`;
  }
}

/** Participant list, your display name, and a short activity log of others' edits. */
export class ParticipantsPanel {
  constructor(parent, { state, send }) {
    this.state = state;
    this.send = send;
    this.list = h('ul', { class: 'participants', testid: 'participants' });
    this.nameInput = h('input', { type: 'text', maxlength: 40, value: displayName(), 'aria-label': 'Your display name', class: 'input small' });
    this.nameInput.addEventListener('change', () => {
      const name = this.nameInput.value.trim().slice(0, 40);
      if (!name) return;
      setDisplayName(name);
      state.name = name;
      if (state.connection === 'connected') this.send(new PresenceCommand(state.selection, name, { source: 'presence' }));
    });
    this.activity = h('ul', { class: 'activity', testid: 'activity' });
    /** participant id → the amount of its fold gesture's last move */
    this.foldAmounts = new Map();
    this.root = h('section', { class: 'panel' },
      h('h3', {}, 'Participants'),
      this.list,
      h('label', { class: 'row' }, h('span', { class: 'muted' }, 'Your name'), this.nameInput),
      this.activity);
    parent.appendChild(this.root);
    state.on('presence', () => this.render());
    state.on('session', () => this.render());
    state.on('edit', (msg) => this._logEdit(msg));
    this.render();
  }

  render() {
    const st = this.state;
    clear(this.list);
    for (const p of st.participants) {
      const doing = p.dragging ? `dragging ${targetLabel(p.dragging)}` : p.selection ? `selected ${targetLabel(p.selection)}` : '';
      this.list.appendChild(h('li', { class: 'participant', testid: 'participant', dataset: { participantId: String(p.id) } },
        h('span', { class: 'swatch', style: { background: p.color || '#888' } }),
        h('span', { class: 'pname' }, p.name || `guest ${p.id}`, p.id === st.you ? h('span', { class: 'muted' }, ' (you)') : null),
        h('span', { class: `badge ${p.role === 'view' ? 'badge-view' : ''}` }, p.role || ''),
        doing ? h('span', { class: 'muted doing' }, doing) : null));
    }
  }

  _logEdit(msg) {
    const p = this.state.participants.find((x) => x.id === msg.by);
    const who = p ? p.name : `participant ${msg.by}`;
    const e = msg.edit || {};
    // A fold gesture is listed at its let-go, with the amount its last move sent.
    if (e.type === 'fold') this.foldAmounts.set(msg.by, e.amount);
    const what = describeEdit(e, { foldAmount: this.foldAmounts.get(msg.by) });
    if (e.type === 'fold_end') this.foldAmounts.delete(msg.by);
    if (!what) return; // drags and fold moves are shown live in the view
    this.activity.prepend(h('li', {}, h('span', { class: 'swatch', style: { background: (p && p.color) || '#888' } }), `${who} ${what}`));
    while (this.activity.children.length > 5) this.activity.lastChild.remove();
  }
}

/** Edit/view links (readonly inputs + copy). */
export class SharePanel {
  constructor(parent, { state }) {
    this.state = state;
    const row = (label, testid) => {
      const input = h('input', { type: 'text', readonly: true, class: 'input share', testid, 'aria-label': `${label} link`, onfocus: (e) => e.target.select() });
      const status = h('span', { class: 'copied', 'aria-live': 'polite' });
      const button = h('button', { class: 'btn small', onclick: async () => {
        if (!input.value) return;
        status.textContent = (await copyText(input.value, input)) ? 'copied' : 'select + Ctrl+C';
        setTimeout(() => { status.textContent = ''; }, 2000);
      } }, 'Copy');
      return { input, el: h('div', { class: 'share-row' }, h('span', { class: 'share-label' }, label), input, button, status) };
    };
    this.edit = row('Edit', 'share-edit');
    this.view = row('View', 'share-view');
    this.root = h('section', { class: 'panel' }, h('h3', {}, 'Share'), this.edit.el, this.view.el,
      h('p', { class: 'muted small' }, 'Anyone with the edit link can change the design; the view link is read-only.'));
    parent.appendChild(this.root);
    state.on('tokens', () => this.render());
    state.on('session', () => this.render());
    this.render();
  }

  link(token) {
    const url = new URL(window.location.href);
    url.search = '';
    url.hash = '';
    url.searchParams.set('session', this.state.session || '');
    url.searchParams.set('token', token);
    return url.toString();
  }

  render() {
    const { edit, view } = this.state.tokens;
    this.edit.input.value = edit && this.state.session ? this.link(edit) : '';
    this.edit.input.placeholder = this.state.role === 'view' ? 'not available with a view link' : '';
    this.view.input.value = view && this.state.session ? this.link(view) : '';
    this.view.input.placeholder = 'unknown here (ask whoever created the session)';
  }
}

export { cutAlongSeams } from './exportFormats.js';

/** Export (server route, Bearer token) and save-scene buttons. */
/** Millimetres per design unit (the scene's `units`). */
const MM_PER_UNIT = { mm: 1, cm: 10, m: 1000, in: 25.4 };

/**
 * A note when the design would print smaller than 20 mm across (`size`: its diagonal in design
 * units) or larger than 2 m: the flat patterns are at true size, one unit the scene's `units`.
 * Else null.
 */
export function printSizeNote(size, units) {
  const mm = MM_PER_UNIT[units] || 1;
  if (!(size > 0)) return null;
  const across = size * mm;
  const shown = across < 10 ? across.toPrecision(2) : String(Math.round(across));
  if (across < 20)
    return `At 1 unit = 1 ${units} this design is ${shown} mm across: SVG, DXF and STL come out that size. Pick a larger unit to print it larger.`;
  if (across > 2000)
    return `At 1 unit = 1 ${units} this design is ${Math.round(across / 1000)} m across: SVG, DXF and STL come out that size. Pick a smaller unit to print it smaller.`;
  return null;
}

export class ExportPanel {
  constructor(parent, { state, toasts, errorSlots, token, currentScene, send, designSize }) {
    this.state = state;
    this.sizeNote = h('p', { class: 'muted small', testid: 'print-size-note', hidden: true });
    // What one coordinate is: STEP and IGES are written in it, FOLD names it, STL, SVG and DXF are
    // written at true size in millimetres from it (set_units; undoable, shared with collaborators).
    this.units = h('select', { testid: 'units-select', title: 'What one coordinate of the design is; the exports follow (the numbers stay)',
      onchange: () => send && send(new SetUnitsCommand(this.units.value, { source: 'export:units' })) },
    ...UNITS.map((u) => h('option', { value: u }, u)));
    const run = (format) => async () => {
      try {
        const blob = await exportSession(state.session, token, format);
        const file = format === 'unfolding_obj' ? '-unfolding.obj' : format === 'iges' ? '.igs' : `.${format}`;
        download(blob, `${slug(state.scene && state.scene.name, state.session)}${file}`);
      } catch (e) {
        const msg = { code: e.code || 'error', message: e.message };
        errorSlots.show('export', msg.message);
        toasts.showError(msg, `export ${format}`);
      }
    };
    this.root = h('section', { class: 'panel' },
      h('h3', {}, 'Export'),
      h('div', { class: 'button-row' },
        h('button', { class: 'btn', testid: 'export-json', title: 'The current scene as a devsurf scene file (from the server)', onclick: run('json') }, 'Export JSON'),
        this.objButton = h('button', { class: 'btn', testid: 'export-obj', title: 'The sampled surface as OBJ quads (from the server)', onclick: run('obj') }, 'Export OBJ'),
        this.foldButton = h('button', { class: 'btn', testid: 'export-fold', title: 'The crease pattern as FOLD 1.2 (composites with a development)', onclick: run('fold') }, 'Export FOLD'),
        this.svgButton = h('button', { class: 'btn', testid: 'export-svg', title: 'The fold pattern as SVG in millimetres: mountain red dash-dot, valley blue dashed', onclick: run('svg') }, 'Export SVG'),
        this.unfoldingObjButton = h('button', { class: 'btn', testid: 'export-unfolding-obj', title: 'The unfolding M′ as an OBJ mesh (from the server)', onclick: run('unfolding_obj') }, 'Export OBJ of M′'),
        this.stlButton = h('button', { class: 'btn', testid: 'export-stl', title: 'The surface as STL triangles in millimetres, for 3D printing and CAD (from the server)', onclick: run('stl') }, 'Export STL'),
        this.dxfButton = h('button', { class: 'btn', testid: 'export-dxf', title: 'The flat pattern as DXF in millimetres, one layer per tool (from the server)', onclick: run('dxf') }, 'Export DXF'),
        this.igesButton = h('button', { class: 'btn', testid: 'export-iges', title: 'The spline surface as IGES B-spline surfaces, one per patch, in the scene\'s units (from the server)', onclick: run('iges') }, 'Export IGES'),
        this.stepButton = h('button', { class: 'btn', testid: 'export-step', title: 'The spline surface as STEP, its patches sewn into one shell (from the server)', onclick: run('step') }, 'Export STEP'),
        h('button', { class: 'btn', testid: 'save-scene', title: 'Save the scene as shown, with the current control points (Ctrl+S)', onclick: () => this.saveScene(currentScene) }, 'Save scene file')),
      h('label', { class: 'small units-row' }, 'Units ', this.units),
      this.sizeNote,
      errorSlots.slot('export'), errorSlots.slot('export:units'));
    parent.appendChild(this.root);
    const update = () => {
      this.units.value = (state.scene && state.scene.units) || 'mm';
      this.units.disabled = !state.canEdit;
      const composite = state.kind === 'composite';
      const quad = state.kind === 'quad_mesh';
      const model = state.scene && state.scene.model;
      // A composite without a development is pieces cut along seams (a shape's cover): no crease
      // pattern, but each piece's flat pattern.
      const pieces = composite && cutAlongSeams(model);
      const development = composite && !!(model && model.development);
      const offered = new Set(exportFormats(state.kind, model));
      const buttons = { obj: this.objButton, stl: this.stlButton, fold: this.foldButton, svg: this.svgButton,
        dxf: this.dxfButton, unfolding_obj: this.unfoldingObjButton, iges: this.igesButton, step: this.stepButton };
      for (const [format, button] of Object.entries(buttons)) button.hidden = !offered.has(format);
      const spline = quad && !!(model && model.control);
      this.igesButton.title = spline ? 'The spline surface as IGES B-spline surfaces, one per patch, in the scene\'s units (from the server)'
        : 'The surface as IGES B-spline surfaces and its curves, in the scene\'s units (from the server)';
      this.stepButton.title = spline ? 'The spline surface as STEP, its patches sewn into one shell (from the server)'
        : 'The surface as STEP B-spline faces, for CAD (from the server)';
      this.objButton.textContent = quad ? 'Export OBJ of M' : 'Export OBJ';
      this.objButton.title = quad ? 'The mesh M as an OBJ mesh (from the server)' : 'The sampled surface as OBJ quads (from the server)';
      this.stlButton.title = quad ? 'The mesh M as STL triangles in millimetres (from the server)'
        : 'The surface as STL triangles in millimetres, for 3D printing and CAD (from the server)';
      this.foldButton.title = quad ? 'M and M′ as FOLD 1.2 with both frames'
        : pieces ? 'The flat pieces and their places on the surface as FOLD 1.2: seams as joins (J), numbered as on the SVG'
          : 'The crease pattern as FOLD 1.2 (composites with a development)';
      this.svgButton.title = quad ? 'The cutting pattern of M′ at true size: cuts, glue edges numbered in pairs'
        : pieces ? 'The flat pieces at true size, cut along the seams: each seam numbered on both of its pieces'
          : development ? 'The fold pattern as SVG in millimetres: mountain red dash-dot, valley blue dashed'
            : 'The flat pattern at true size: the strip unrolled, its rulings as faint lines';
      this.dxfButton.title = development
        ? 'The crease pattern as DXF in millimetres: layers CUT (outline), MOUNTAIN and VALLEY (score), RULINGS (off)'
        : quad || pieces ? 'The cutting pattern as DXF in millimetres: layers CUT, GLUE (cut, then glue) and LABEL (seam numbers)'
          : 'The flat pattern as DXF in millimetres: the strip unrolled, its outline on layer CUT';
    };
    state.on('scene', update);
    state.on('editable', update);
    update();
    // The print size once the design is drawn (its size is the drawn geometry's until a sheet's).
    const showSize = () => {
      const note = designSize ? printSizeNote(designSize(), (state.scene && state.scene.units) || 'mm') : null;
      this.sizeNote.hidden = !note;
      this.sizeNote.textContent = note || '';
    };
    state.on('scene', showSize);
    state.on('geometry', ({ source }) => { if (source !== 'iterate') queueMicrotask(showSize); });
    state.on('solved', () => queueMicrotask(showSize));
  }

  saveScene(currentScene) {
    const scene = currentScene();
    if (!scene) return;
    download(`${JSON.stringify(scene, null, 2)}\n`, `${slug(scene.name, this.state.session)}.devsurf.json`, 'application/json');
  }
}

/** The selected control point: position, fixed/handle state, buttons (F / H). */
export class SelectionPanel {
  /**
   * @param {object} deps  {state, pointOf(target) → [x,y,z]|null, errorSlots, toggleFixed, toggleHandle,
   *   moveTo(target, [x,y,z]) — a drag to typed coordinates and its release, designSize() → number
   *   or null (not known yet)}
   */
  constructor(parent, { state, pointOf, errorSlots, toggleFixed, toggleHandle, moveTo, designSize }) {
    this.state = state;
    this.pointOf = pointOf;
    this.moveTo = moveTo;
    this.designSize = designSize || (() => null);
    this.title = h('div', { class: 'sel-title' });
    this.coords = h('div', { class: 'sel-coords num' });
    this.fixButton = h('button', { class: 'btn', testid: 'toggle-fixed', title: 'Fix / unfix the selected point (F)', onclick: toggleFixed }, 'Fix');
    this.handleButton = h('button', { class: 'btn', testid: 'toggle-handle', title: 'Add / remove a handle at the selected point (H)', onclick: toggleHandle }, 'Add handle');
    this.hint = h('p', { class: 'muted small' }, 'Click a point to select it; drag it to reshape the design. The solver keeps it developable.');
    this.buttons = h('div', { class: 'button-row' }, this.fixButton, this.handleButton);
    // Exact input: coordinates typed for the selected point (a drag there and its release).
    this.inputs = ['x', 'y', 'z'].map((axis) => h('input', {
      type: 'number', step: 'any', class: 'coord-input', testid: `coord-${axis}`, 'aria-label': `${axis} of the selected point`,
      onkeydown: (e) => { if (e.key === 'Enter') this.submitCoordinates(); },
    }));
    this.moveButton = h('button', { class: 'btn small', testid: 'move-to', title: 'Pull the selected point to these coordinates (Enter); the solver keeps the design developable', onclick: () => this.submitCoordinates() }, 'Move');
    this.coordRow = h('div', { class: 'row coord-row' }, ...this.inputs.flatMap((input, k) => [h('span', { class: 'muted small' }, 'xyz'[k]), input]), this.moveButton);
    // How a drag moves: held to an axis or a plane through the point, snapped to a grid.
    this.constraint = h('select', { testid: 'drag-constraint', title: 'Hold a drag to an axis or a coordinate plane through the point (X, Y, Z while dragging; Shift for the plane across)', onchange: () => this.storeDragOptions() },
      ...DRAG_CONSTRAINTS.map((c) => h('option', { value: c }, c === 'free' ? 'free (view plane)' : c.length === 1 ? `${c} axis` : `${c} plane`)));
    this.snap = h('input', { type: 'checkbox', testid: 'snap-grid', onchange: () => this.storeDragOptions() });
    this.step = h('input', { type: 'number', step: 'any', min: '0', class: 'coord-input', testid: 'snap-step', 'aria-label': 'grid step', onchange: () => this.storeDragOptions() });
    this.dragRow = h('div', { class: 'row drag-options' },
      h('label', { class: 'small' }, 'Drag ', this.constraint),
      h('label', { class: 'small', title: 'Snap dragged coordinates to multiples of the step (design units)' }, this.snap, ' snap ', this.step));
    this.root = h('section', { class: 'panel' }, h('h3', {}, 'Selection'), this.title, this.coords, this.coordRow, this.dragRow, this.buttons,
      errorSlots.slot('selection:fix'), errorSlots.slot('selection:handle'), errorSlots.slot('selection:move'), this.hint);
    this.errorSlots = errorSlots;
    parent.appendChild(this.root);
    for (const ev of ['selection', 'scene', 'session', 'iterate', 'editable']) state.on(ev, () => this.render());
    // The point's coordinates come from the drawn geometry, which its listeners update after the
    // scene and iterate events (an undo's answer: the fields kept the undone drag's values, and
    // Move would send it again): once every listener has run, the fields follow.
    state.on('geometry', () => queueMicrotask(() => this.render()));
    // A release answers a typed move: from then on the fields follow the point again (a move the
    // server accepts may leave it where it was: a fixed point, the coordinates it had).
    state.on('solved', () => {
      this.typed = null;
      this.render();
    });
    // The grid step follows the design's size until the user types one (the editor also calls
    // followDesignSize once new geometry is drawn).
    state.on('scene', () => this.followDesignSize());
    this.step.addEventListener('input', () => { this.stepTyped = true; });
    this.storeDragOptions();
    state.on('drag-options', (o) => { if (o && o.constraint) this.constraint.value = o.constraint; });
    this.render();
  }

  /**
   * Sets the grid step from the design's size (`designSize()`: a drawn sheet's diagonal, else the
   * drawn surface's; null while neither is known, when the step waits) unless one was typed.
   */
  followDesignSize() {
    if (this.stepTyped) return;
    const size = this.designSize();
    if (!(size > 0)) return;
    const step = String(defaultGridStep(size));
    if (this.step.value !== step) {
      this.step.value = step;
      this.storeDragOptions();
    }
  }

  /** The drag options, read by the 3D view's pointer handling. */
  storeDragOptions() {
    const step = Number(this.step.value);
    this.state.dragOptions = { constraint: this.constraint.value, snap: this.snap.checked, step: Number.isFinite(step) && step > 0 ? step : 0 };
  }

  /** Sets the constraint (keys X, Y, Z while dragging). */
  setConstraint(c) {
    if (!DRAG_CONSTRAINTS.includes(c)) return;
    this.constraint.value = c;
    this.storeDragOptions();
  }

  submitCoordinates() {
    const sel = this.state.selection;
    const current = sel && this.pointOf(sel);
    if (!current) return;
    // A number input hands over '' for text it cannot read ("abc", "1e999"): its validity says so.
    const unreadable = this.inputs.findIndex((input) => input.validity && input.validity.badInput);
    if (unreadable >= 0) {
      this.errorSlots.show('selection:move', `${'xyz'[unreadable]}: enter a number`);
      return;
    }
    const position = this.inputs.map((input, k) => (input.value.trim() === '' ? current[k] : Number(input.value)));
    const bad = position.findIndex((x) => !Number.isFinite(x));
    if (bad >= 0) {
      this.errorSlots.show('selection:move', `${'xyz'[bad]}: enter a finite number`);
      return;
    }
    if (this.state.isFixed(sel)) {
      this.errorSlots.show('selection:move', 'this point is fixed: unfix it (F) to move it');
      return;
    }
    this.errorSlots.clear('selection:move');
    // The fields are left as typed until the point moves or a release answers (render): a move
    // the server refuses — no release follows it — leaves the text there to correct, beside the
    // message that names it.
    this.typed = { target: sel, at: current.slice() };
    this.moveTo(sel, position);
  }

  render() {
    const st = this.state;
    const sel = st.selection;
    const p = sel && this.pointOf(sel);
    this.buttons.hidden = !p || this.editsConstraints === false;  // strips between curves: no fix/handle
    this.coords.hidden = !p;
    this.coordRow.hidden = !p;
    this.hint.hidden = !!p;
    this.hint.textContent = st.role === 'view'
      ? 'Click a point to see where it is. This link is view only: it cannot change the design.'
      : 'Click a point to select it; drag it to reshape the design. The solver keeps it developable.';
    const editable = st.canEdit;
    this.dragRow.hidden = st.role !== 'edit';
    if (!p) {
      this.title.textContent = 'Nothing selected';
      this.shownFor = null;
      this.typed = null;
      return;
    }
    const fixed = st.isFixed(sel);
    const handle = st.constraints.handles.find((x) => sameTarget(x, sel));
    const label = targetLabel(sel);
    this.title.textContent = `${sel.curve !== undefined ? `Control point ${label}` : label[0].toUpperCase() + label.slice(1)} — ${fixed ? 'fixed' : 'free'}${handle ? ', with handle' : ''}`;
    this.coords.textContent = `x ${formatFixed(p[0], 3)}   y ${formatFixed(p[1], 3)}   z ${formatFixed(p[2], 3)}`;
    // The inputs follow the point unless being typed in (a new selection always refills them),
    // or typed and sent until the point moves or a release answers (submitCoordinates).
    const fresh = !sameTarget(this.shownFor, sel);
    this.shownFor = sel;
    const typed = !fresh && editable && this.typed && sameTarget(this.typed.target, sel) &&
      this.typed.at.every((v, k) => v === p[k]) ? this.typed : null;
    this.typed = typed;
    this.inputs.forEach((input, k) => {
      if (!typed && (fresh || document.activeElement !== input)) input.value = String(Number(p[k].toFixed(6)));
      input.disabled = !editable;
    });
    this.moveButton.disabled = !editable;
    this.fixButton.textContent = fixed ? 'Unfix (F)' : 'Fix (F)';
    this.handleButton.textContent = handle ? 'Remove handle (H)' : 'Add handle (H)';
    this.fixButton.disabled = !editable;
    this.handleButton.disabled = !editable;
  }
}

/** Colour legend over the 3D view: warp angle (strips), face flatness or vertex curvature (composites). */
export class Legend {
  constructor(parent) {
    this.max = h('span', {}, '1°');
    this.min = h('span', {}, '0°');
    this.current = h('span', {
      class: 'legend-current',
      title: 'Largest value among the drawn samples. The status bar reports the solver\'s metric, taken at its own (denser) samples.',
    });
    this.title = h('div', { class: 'legend-title', testid: 'legend-title' }, 'warp angle');
    this.bar = h('div', { class: 'legend-bar', style: { background: cssGradient() } });
    this.root = h('div', { class: 'legend', 'aria-label': 'Colour scale' },
      this.title,
      this.bar,
      h('div', { class: 'legend-labels' }, this.min, this.current, this.max));
    parent.appendChild(this.root);
  }

  /**
   * @param {object} [scale] {title, unit, diverging} (default: warp angle in degrees); a diverging
   * scale runs from −range (blue) through 0 to +range (red), `max` is then the largest |value|.
   */
  update(range, max, scale = { title: 'warp angle', unit: '°' }) {
    this.showCategories(null);
    const unit = scale.unit;
    this.title.textContent = scale.title;
    const fmt = (x) => (Math.abs(x) < 0.01 ? formatExponential(x, 1) : formatNumber(x, 2));
    const diverging = !!scale.diverging;
    if (this._diverging !== diverging) {
      this.bar.style.background = diverging ? cssDivergingGradient() : cssGradient();
      this._diverging = diverging;
    }
    this.min.textContent = diverging ? `−${fmt(range)}${unit}` : `0${unit}`;
    this.root.dataset.scale = diverging ? 'diverging' : 'sequential';
    this.max.textContent = `${fmt(range)}${unit}`;
    this.current.textContent = diverging ? `max |·| ${fmt(max)}${unit}` : `drawn max ${fmt(max)}${unit}`;
  }

  /** A categorical legend ([{label, color (CSS)}]) instead of the scale; null returns to the scale. */
  showCategories(categories, title) {
    if (!this.categories) {
      this.categories = h('div', { class: 'legend-categories', hidden: true });
      this.root.appendChild(this.categories);
    }
    const on = !!(categories && categories.length);
    this.root.classList.toggle('legend-categorical', on);
    this.categories.hidden = !on;
    if (!on) return;
    if (title) this.title.textContent = title;
    clear(this.categories);
    for (const c of categories) {
      this.categories.appendChild(h('span', { class: 'legend-category' }, h('span', { class: 'legend-swatch', style: { background: c.color } }), c.label));
    }
  }
}

/**
 * Composites: the selected interior edge (click its diamond in the 3D view or pick it here), its
 * fold (assignment, mean fold angle) and its crease type, switched with a SetCreaseCommand.
 */
export class CreasePanel {
  constructor(parent, { state, composite, send, errorSlots }) {
    this.state = state;
    this.composite = composite;
    this.send = send;
    this.edgeSelect = h('select', { class: 'input small', testid: 'crease-edge', 'aria-label': 'Edge' });
    this.edgeSelect.addEventListener('change', () => state.setSelectedEdge(this.edgeSelect.value === '' ? null : Number(this.edgeSelect.value)));
    this.typeSelect = h('select', { class: 'input small', testid: 'crease-type', 'aria-label': 'Crease type' },
      CREASE_KINDS.map((k) => h('option', { value: k }, k)));
    this.typeSelect.addEventListener('change', () => {
      const e = state.selectedEdge;
      if (e === null) return;
      this.send(new SetCreaseCommand(e, this.typeSelect.value, { source: 'crease:type' }));
    });
    this.info = h('div', { class: 'crease-info num', testid: 'crease-info' });
    // Editing the labelled mesh (000_… §4.1): R ↔ S, a face split between two corners, the two
    // faces of an edge joined. Composites made from a drawing change through their drawing.
    this.relabelButton = h('button', { class: 'btn small', testid: 'relabel-edge', onclick: () => this.relabel() }, 'Make S');
    this.oppositeToggle = h('input', { type: 'checkbox', checked: true, testid: 'relabel-opposite',
      onchange: () => { this._meshKey = null; this.render(); } });
    // Why the picked edge cannot be relabelled or its faces joined (the buttons are disabled then).
    this.meshHint = h('p', { class: 'muted small', testid: 'labelled-mesh-hint', hidden: true });
    this.mergeButton = h('button', { class: 'btn small', testid: 'merge-faces', onclick: () => this.merge() }, 'Join its faces');
    this.splitButton = h('button', { class: 'btn small', testid: 'split-face', onclick: () => this.split() }, 'Split the face');
    this.splitHint = h('span', { class: 'muted small', testid: 'split-face-hint' });
    // A vertex added at the middle of the picked ruling, or the selected vertex removed.
    this.addVertexButton = h('button', { class: 'btn small', testid: 'split-edge', onclick: () => this.addVertex() }, 'Add a vertex');
    this.removeVertexButton = h('button', { class: 'btn small', testid: 'remove-vertex', onclick: () => this.removeVertex() }, 'Remove vertex');
    // A new ruling across the picked curve's strips, at a percentage of the curve.
    this.cutButton = h('button', { class: 'btn small', testid: 'split-along-ruling', onclick: () => this.cutAcross() }, 'Cut across');
    this.cutAt = h('input', { class: 'input small num', type: 'number', min: 1, max: 99, step: 1, value: 50, testid: 'split-along-ruling-at',
      'aria-label': 'Where along the curve, in percent', style: { width: '4.5em' } });
    this.meshEdits = h('div', { class: 'labelled-mesh', testid: 'labelled-mesh-edits' },
      h('div', { class: 'row' }, this.relabelButton,
        h('label', { class: 'small', title: 'The side across each four-sided face of the edge, if it has the same label: a strip needs both its curves, a planar quad made a strip both sides' },
          this.oppositeToggle, ' and the opposite sides'),
        this.mergeButton),
      this.meshHint,
      h('div', { class: 'row' }, this.splitButton, this.splitHint),
      h('div', { class: 'row' }, this.cutButton, h('label', { class: 'small' }, 'at ', this.cutAt, ' % of the curve')),
      h('div', { class: 'row' }, this.addVertexButton, this.removeVertexButton),
      errorSlots.slot('crease:mesh'));
    this.drawnNote = h('p', { class: 'muted small', hidden: true }, 'Made from a drawing: split and join faces, bend creases and set their kind on the crease board.');
    this.root = h('section', { class: 'panel', testid: 'crease-panel', hidden: true },
      h('h3', {}, 'Crease'),
      h('label', { class: 'row' }, h('span', { class: 'muted' }, 'Edge'), this.edgeSelect),
      h('label', { class: 'row' }, h('span', { class: 'muted' }, 'Type'), this.typeSelect),
      this.info,
      errorSlots.slot('crease:type'),
      this.meshEdits, this.drawnNote,
      h('p', { class: 'muted small' }, 'fold: curved fold (eq. 7) · geodesic: mirror-image developments (eq. 8) · smooth: one tangent plane · none: free. Click a diamond in the 3D view to pick an edge; Shift-click two corners of a face to split it; pick a curve and Cut across to add a ruling through its strips.'));
    parent.appendChild(this.root);
    for (const ev of ['scene', 'edge-selection', 'session', 'group', 'selection', 'editable']) state.on(ev, () => this.render());
    this.render();
  }

  /** The scene's model when its labelled mesh can be edited here (a composite without a drawing). */
  _editableModel() {
    const model = this.state.scene && this.state.scene.model;
    if (!model || model.kind !== 'composite' || model.drawing) return null;
    return model;
  }

  /** The two corners of the group selection that can split a face, or null. */
  _splitTarget() {
    const model = this._editableModel();
    const g = this.state.group || [];
    if (!model || g.length !== 2 || !g.every((t) => Number.isInteger(t.vertex))) return null;
    return splitCandidate(model, g[0].vertex, g[1].vertex);
  }

  relabel() {
    const model = this._editableModel();
    const e = this.state.selectedEdge;
    if (!model || e === null || !model.edges[e]) return;
    const label = model.edges[e].type === 'S' ? 'R' : 'S';
    this.send(new RelabelEdgeCommand(relabelGroup(model, e, this.oppositeToggle.checked), label, { source: 'crease:mesh' }));
  }

  merge() {
    const e = this.state.selectedEdge;
    if (!this._editableModel() || e === null) return;
    this.state.setSelectedEdge(null);
    this.send(new MergeFacesCommand(e, { source: 'crease:mesh' }));
  }

  addVertex() {
    const model = this._editableModel();
    const e = this.state.selectedEdge;
    if (!model || e === null || !model.edges[e] || model.edges[e].type !== 'R') return;
    this.send(new SplitEdgeCommand(e, 0.5, { source: 'crease:mesh' }));
  }

  removeVertex() {
    const sel = this.state.selection;
    if (!this._editableModel() || !sel || !Number.isInteger(sel.vertex)) return;
    this.state.setSelection(null);
    this.send(new RemoveVertexCommand(sel.vertex, { source: 'crease:mesh' }));
  }

  cutAcross() {
    const model = this._editableModel();
    const e = this.state.selectedEdge;
    if (!model || e === null || !model.edges[e] || model.edges[e].type !== 'S') return;
    const percent = Math.min(99, Math.max(1, Number(this.cutAt.value) || 50));
    this.send(new SplitAlongRulingCommand(e, percent / 100, { source: 'crease:mesh' }));
  }

  split() {
    const target = this._splitTarget();
    if (!target) return;
    this.state.setGroup([]);
    this.send(new SplitFaceCommand(target.face, target.vertices, { source: 'crease:mesh' }));
  }

  _renderMeshEdits() {
    const st = this.state;
    const model = st.scene && st.scene.model;
    // render() runs after every iterate's geometry: redo this only when what it reads changed.
    const key = [st.scene, st.selectedEdge, st.canEdit, JSON.stringify(st.group || []), JSON.stringify(st.selection || null)];
    if (this._meshKey && key.every((k, i) => k === this._meshKey[i])) return;
    this._meshKey = key;
    const editable = this._editableModel();
    this.drawnNote.hidden = !(model && model.drawing);
    this.meshEdits.hidden = !editable;
    if (!editable) return;
    const canEdit = st.canEdit;
    const e = st.selectedEdge;
    const edge = e === null ? null : editable.edges[e];
    const to = edge && edge.type === 'S' ? 'R' : 'S';
    this.relabelButton.textContent = `Make ${to}`;
    // The labels the faces would get, judged here as the server judges them: a button that can
    // only be refused is disabled, and the hint says why in words.
    const relabelWhy = edge ? relabelProblem(editable, relabelGroup(editable, e, this.oppositeToggle.checked), to) : null;
    const mergeWhy = edge ? mergeProblem(editable, e) : null;
    this.relabelButton.title = !edge ? 'Pick an edge first'
      : relabelWhy ? `Edge ${e} cannot be made ${to}: ${relabelWhy}`
        : `Relabel edge ${e} ${to === 'R' ? 'a ruling (R): its curve becomes its chord' : 'a spline (S): a straight curve you can then bend'}`;
    this.relabelButton.disabled = !edge || !canEdit || !!relabelWhy;
    this.mergeButton.title = mergeWhy ? `The faces of edge ${e} cannot be joined: ${mergeWhy}` : 'Remove this edge: its two faces become one';
    this.mergeButton.disabled = !edge || !canEdit || !!mergeWhy;
    const hints = [relabelWhy && `Make ${to}: ${relabelWhy}.`, mergeWhy && `Join: ${mergeWhy}.`].filter(Boolean);
    this.meshHint.textContent = hints.join(' ');
    this.meshHint.hidden = !hints.length;
    const split = this._splitTarget();
    this.splitButton.disabled = !split || !canEdit;
    const curve = !!edge && edge.type === 'S';
    this.cutButton.disabled = !curve || !canEdit;
    this.addVertexButton.disabled = !edge || edge.type !== 'R' || !canEdit;
    this.addVertexButton.title = edge && edge.type === 'R' ? `A vertex at the middle of edge ${e}: the faces on it get a corner there (then split a face from it)` : 'Pick a ruling (R edge) first';
    const vertex = st.selection && Number.isInteger(st.selection.vertex) ? st.selection.vertex : null;
    this.removeVertexButton.disabled = vertex === null || !canEdit;
    this.removeVertexButton.title = vertex === null ? 'Select a vertex where two rulings meet' : `Remove vertex ${vertex}: its two rulings become one edge`;
    this.cutAt.disabled = !curve || !canEdit;
    this.cutButton.title = curve ? `A new ruling across the strips of edge ${e} (and of every curve sharing its spline space), at this percentage of the curve; each strip becomes two and nothing moves`
      : 'Pick a spline edge (S) first';
    const g = st.group || [];
    this.splitHint.textContent = split ? `face ${split.face}: a ruling from vertex ${split.vertices[0]} to ${split.vertices[1]}`
      : g.length === 2 ? 'these two points are not opposite corners of one face' : 'Shift-click two corners of a face';
  }

  /** Called by the editor after each composite geometry update (and on the signals above). */
  render() {
    const st = this.state;
    this.root.hidden = st.kind !== 'composite';
    if (this.root.hidden) return;
    this._renderMeshEdits();
    // Interior edges (creases); with the labelled mesh editable, boundary edges too (a side of a
    // face to relabel).
    const edges = this.composite.edges.filter((e) => e.interior || !this.meshEdits.hidden);
    const signature = edges.map((e) => `${e.edge}${e.type}${e.crease}${e.interior}`).join();
    if (signature !== this._signature) {
      const options = [h('option', { value: '' }, edges.length ? '— select an edge —' : 'no interior edges')];
      for (const e of edges) options.push(h('option', { value: String(e.edge) }, `edge ${e.edge} · ${e.type} · ${e.interior ? e.crease : 'boundary'}`));
      this.edgeSelect.replaceChildren(...options);
      this._signature = signature;
    }
    this.edgeSelect.value = st.selectedEdge === null ? '' : String(st.selectedEdge);
    const edge = st.selectedEdge === null ? null : this.composite.edge(st.selectedEdge);
    this.typeSelect.value = edge ? this._sceneCrease(edge.edge) : 'none';
    // A drawn design is rebuilt from its drawing at every board edit, which would drop a type set
    // here without a word: its creases are what the board says (M/V/F, curved creases as folds).
    const drawn = !!(st.scene && st.scene.model && st.scene.model.drawing);
    this.typeSelect.disabled = !edge || !edge.interior || !st.canEdit || drawn;
    this.typeSelect.title = drawn ? 'Made from a drawing: its creases are set on the crease board' : '';
    for (const o of this.typeSelect.options) o.disabled = !!edge && edge.type === 'R' && (o.value === 'fold' || o.value === 'geodesic');
    if (!edge) {
      this.info.textContent = '';
      return;
    }
    const name = { M: 'mountain', V: 'valley', F: 'flat', B: 'boundary' }[edge.assignment] || edge.assignment;
    this.info.textContent = `${edge.type} edge, vertices ${edge.v[0]}→${edge.v[1]} · ${name} · fold ${formatFixed(edge.foldAngleDeg, 1)}°`;
  }

  /** The crease type as the scene says. */
  _sceneCrease(e) {
    const edges = this.state.scene && this.state.scene.model && this.state.scene.model.edges;
    return (edges && edges[e] && edges[e].crease) || 'none';
  }
}
