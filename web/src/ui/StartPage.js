// Start page: demo sessions, new session from a bundled preset, open a scene file or import a
// FOLD crease pattern (input or drag-and-drop anywhere on the page), join by link.

import { h, clear } from './dom.js';
import { PRESETS } from '../presets.js';
import { approximateMesh, createSession, fitRegion, importCreasePattern, listSessions, previewShape, sessionThumbnail } from '../net/api.js';
import { RegionPicker } from './RegionPicker.js';
import { blankSheetCard } from './blankSheet.js';
import { Toasts } from './Toast.js';
import { UNITS } from '../commands/SetUnitsCommand.js';
import { apiKey, forgetSession, openedSessions, rememberSessionTokens, setApiKey } from './preferences.js';

export function editorUrl(session, token) {
  const url = new URL(window.location.href);
  url.search = '';
  url.hash = '';
  url.searchParams.set('session', session);
  url.searchParams.set('token', token);
  return url.toString();
}

/** Parses a pasted link (or "session token", or a query string) into {session, token}. */
export function parseJoinInput(text) {
  const s = String(text || '').trim();
  if (!s) return null;
  try {
    const url = new URL(s, window.location.href);
    const session = url.searchParams.get('session');
    const token = url.searchParams.get('token');
    if (session && token) return { session, token };
  } catch {
    /* not a URL */
  }
  const parts = s.split(/[\s,]+/);
  if (parts.length === 2) return { session: parts[0], token: parts[1] };
  return null;
}

/** Points (n × 3 flattened) as an XYZ file: one "x y z" line per point. */
function xyzBlob(positions) {
  const lines = [];
  for (let i = 0; i < positions.length; i += 3) lines.push(`${positions[i]} ${positions[i + 1]} ${positions[i + 2]}`);
  return new Blob([lines.join('\n') + '\n'], { type: 'text/plain' });
}

/**
 * Loads session thumbnails (GET /api/sessions/{id}/thumbnail, PNGs the server renders once per
 * revision) a few at a time, so a page of demos does not queue dozens of requests at once.
 */
export class ThumbnailLoader {
  constructor({ concurrency = 4, fetchThumbnail = sessionThumbnail } = {}) {
    this.concurrency = concurrency;
    this.fetchThumbnail = fetchThumbnail;
    this.queue = [];
    this.running = 0;
  }

  /** An <img> that shows the session's picture when it arrives; `onMissing(error)` if it cannot. */
  image(id, token, { alt = '', onMissing = null } = {}) {
    const img = h('img', { class: 'thumb', testid: 'session-thumbnail', alt, width: 320, height: 240, dataset: { sessionId: id, state: 'loading' } });
    this.queue.push({ id, token, img, onMissing });
    this._next();
    return img;
  }

  _next() {
    while (this.running < this.concurrency && this.queue.length) {
      const job = this.queue.shift();
      this.running++;
      this.fetchThumbnail(job.id, job.token)
        .then((blob) => {
          job.img.src = URL.createObjectURL(blob);
          job.img.dataset.state = 'loaded';
        })
        .catch((e) => {
          job.img.dataset.state = 'missing';
          job.img.hidden = true;
          if (job.onMissing) job.onMissing(e);
        })
        .finally(() => {
          this.running--;
          this._next();
        });
    }
  }
}

export class StartPage {
  constructor(root, { state }) {
    this.state = state;
    this.toasts = new Toasts(document.body);
    this.demoList = h('div', { class: 'demo-list', 'aria-busy': 'true' }, h('p', { class: 'muted' }, 'Loading demo sessions…'));
    this.thumbnails = new ThumbnailLoader();
    this.mySessionList = h('div', { class: 'demo-list' });
    this.mySessions = h('section', { class: 'card wide', testid: 'my-sessions', hidden: true },
      h('h2', {}, 'Your sessions'),
      h('p', { class: 'muted small' }, 'Sessions this browser created or joined, most recent first, with their links.'),
      this.mySessionList);

    this.presetSelect = h('select', { class: 'input', testid: 'preset-select', 'aria-label': 'Example scene' },
      PRESETS.map((p) => h('option', { value: p.id }, p.name)));
    // The summary in plain words; the full description (the papers' figures and equations, the
    // numbers) one click away.
    this.presetSummary = h('p', { class: 'small preset-summary', testid: 'preset-summary' });
    this.presetDetailsText = h('p', { class: 'muted small preset-description' });
    this.presetDescription = h('div', {}, this.presetSummary,
      h('details', { class: 'preset-details' }, h('summary', { class: 'small' }, 'About this example'), this.presetDetailsText));
    this.presetSelect.addEventListener('change', () => this._describePreset());
    this.newButton = h('button', { class: 'btn primary', testid: 'new-session', onclick: () => this._newFromPreset() }, 'New session');

    this.fileInput = h('input', { type: 'file', accept: '.json,.fold,.svg,application/json,image/svg+xml', testid: 'scene-file', class: 'file-input', id: 'scene-file' });
    this.fileInput.addEventListener('change', () => {
      const f = this.fileInput.files && this.fileInput.files[0];
      if (f) this._openFile(f);
    });
    this.dropZone = h('label', { class: 'drop-zone', for: 'scene-file' },
      h('strong', {}, 'Choose a file'), h('span', { class: 'muted' }, ' or drop a .json, .fold or .svg file anywhere on this page'));
    // The units of a crease pattern's numbers: as the file says (FOLD's frame_unit, an SVG's
    // width in mm), or chosen here (an import note says a file without them is scaled).
    this.importUnits = h('select', { class: 'input narrow', testid: 'import-units', 'aria-label': 'Units of a crease pattern\'s numbers' },
      h('option', { value: '' }, 'as the file says'), ...UNITS.map((u) => h('option', { value: u }, u)));
    // What an import changed or left out, by element of the file, before its session is opened.
    this.importNotes = h('div', { class: 'import-notes', testid: 'import-notes', hidden: true });

    // A user's own mesh → glued developable patches (POST /api/approximations), opened as a session.
    this.meshInput = h('input', { type: 'file', accept: '.off,.obj,.ply,.stl', testid: 'mesh-file', class: 'input', 'aria-label': 'Mesh file' });
    this.meshPatches = h('input', { type: 'number', class: 'input narrow', min: '1', max: '1000', value: '8', testid: 'mesh-patches', 'aria-label': 'Patches' });
    this.meshFaces = h('input', { type: 'number', class: 'input narrow', min: '4', max: '100000', value: '1500', testid: 'mesh-faces', 'aria-label': 'Quads' });
    this.meshButton = h('button', { class: 'btn', testid: 'approximate-mesh', onclick: () => this._approximateMesh() }, 'Approximate');

    // A user's shape → a strip fitted to a region, or strips side by side covering it (POST
    // /api/references to draw it, then /api/fits or /api/covers), opened as a session.
    this.shapeInput = h('input', { type: 'file', accept: '.off,.obj,.ply,.stl,.xyz,.pwn', testid: 'shape-file', class: 'input', 'aria-label': 'Shape file' });
    this.shapeInput.addEventListener('change', () => this._previewShape());
    this.shapeInfo = h('p', { class: 'muted small', testid: 'shape-info' }, 'A point cloud (.xyz, .pwn, .ply) or a mesh (.off, .obj, .ply, .stl). Click the shape to centre the region.');
    this.regionCentre = h('input', { type: 'text', class: 'input', testid: 'region-centre', placeholder: 'x, y, z', 'aria-label': 'Region centre' });
    this.regionCentre.addEventListener('change', () => this._updateRegion());
    this.regionRadius = h('input', { type: 'range', min: '1', max: '60', step: '1', value: '15', testid: 'region-radius', 'aria-label': 'Region radius (% of the shape)' });
    this.regionRadius.addEventListener('input', () => this._updateRegion());
    this.regionRadiusLabel = h('span', { class: 'small mono', testid: 'region-radius-label' });
    // How the region is marked: a ball (click a centre), a brush (paint) or a lasso (draw around).
    this.regionTool = h('select', { class: 'input fit', testid: 'region-tool', 'aria-label': 'Region tool' },
      h('option', { value: 'ball' }, 'Ball: click its centre'),
      h('option', { value: 'brush' }, 'Brush: paint the region'),
      h('option', { value: 'lasso' }, 'Lasso: draw around it'));
    this.regionTool.addEventListener('change', () => this._setRegionTool());
    this.regionClear = h('button', { class: 'btn small', testid: 'region-clear', hidden: true, onclick: () => this.regionPicker && this.regionPicker.clearSelection() }, 'Clear');
    this.regionCount = h('span', { class: 'small mono', testid: 'region-count' });
    this.regionHint = h('p', { class: 'muted small', testid: 'region-hint' });
    this.centreField = h('label', { class: 'small' }, 'Centre ', this.regionCentre);
    this.radiusName = h('span', {}, 'Radius ');
    this.regionMode = h('select', { class: 'input fit', testid: 'region-mode', 'aria-label': 'What to fit' },
      h('option', { value: 'strip' }, 'one strip, fitted live'),
      h('option', { value: 'cover' }, 'strips side by side (a composite)'),
      h('option', { value: 'whole' }, 'the whole shape, region by region (Fig. 10e)'));
    this.regionStrips = h('input', { type: 'number', class: 'input narrow', min: '1', max: '64', value: '6', testid: 'region-strips', 'aria-label': 'Strips' });
    // The whole shape: cut into this many clusters by normal, each covered by its own strips.
    this.shapeRegions = h('input', { type: 'number', class: 'input narrow', min: '2', max: '32', value: '24', testid: 'shape-regions', 'aria-label': 'Regions' });
    this.shapeRegionsField = h('label', { class: 'small', hidden: true }, 'Regions ', this.shapeRegions);
    // The server takes regions × strips × 8 sweeps ≤ 1600: the strips' field follows the regions.
    this.shapeRegions.addEventListener('change', () => this._limitStrips());
    this.regionMode.addEventListener('change', () => {
      const mode = this.regionMode.value;
      this.regionStrips.disabled = mode === 'strip';
      if (mode === 'whole' && Number(this.regionStrips.value) > 4) this.regionStrips.value = '4';
      this.shapeRegionsField.hidden = mode !== 'whole';
      this.keepOverField.hidden = mode !== 'strip';
      this._limitStrips();
      this._updateRegion();
    });
    this.regionStrips.addEventListener('change', () => this._updateRegion());
    this.regionStrips.disabled = true;
    // One strip: without overhang rows it grows over all it reaches (the paper's Fig. 11), a flap
    // where the region is doubly curved; with them it stays over the region.
    this.keepOver = h('input', { type: 'checkbox', testid: 'region-keep-over', checked: true, 'aria-label': 'Keep the strip over the region' });
    this.keepOverField = h('label', { class: 'small', title: 'Pull back the parts of the strip that spread beyond the region (overhang weight 0.001); off: the paper\'s equations alone, the strip grows over all it reaches' }, this.keepOver, ' keep over the region');
    this.regionButton = h('button', { class: 'btn', testid: 'fit-region', disabled: true, onclick: () => this._fitRegion() }, 'Fit');
    this.regionPicker = null;
    this.regionView = h('div', { class: 'region-view-slot', hidden: true });

    this.joinInput = h('input', { type: 'text', class: 'input', placeholder: 'paste an edit or view link', 'aria-label': 'Session link' });
    this.joinError = h('div', { class: 'field-error', hidden: true });
    const join = () => {
      const j = parseJoinInput(this.joinInput.value);
      if (!j) {
        this.joinError.textContent = 'Paste a link like …/?session=ID&token=TOKEN';
        this.joinError.hidden = false;
        return;
      }
      window.location.assign(editorUrl(j.session, j.token));
    };
    this.joinInput.addEventListener('keydown', (e) => { if (e.key === 'Enter') join(); });

    this.apiKeyInput = h('input', { type: 'password', class: 'input', placeholder: 'API key', value: apiKey(), 'aria-label': 'API key', autocomplete: 'off' });
    this.apiKeyInput.addEventListener('change', () => setApiKey(this.apiKeyInput.value.trim()));
    this.apiKeyRow = h('form', { class: 'row', hidden: !apiKey(), onsubmit: (e) => e.preventDefault() }, h('span', { class: 'muted small' }, 'This server needs an API key to create sessions:'), this.apiKeyInput);
    this.createError = h('div', { class: 'field-error', hidden: true, role: 'alert' });
    this.busy = h('div', { class: 'muted small', hidden: true }, 'Creating the session…');
    // A blank sheet: its outline imported as an SVG drawing, opened at once.
    this.blankSheet = blankSheetCard(({ svg, name, units }) => this._importCreasePattern({ name: `${name}.svg` }, svg, 'svg', { openAtOnce: true, units }));

    this.root = h('div', { class: 'start-page', testid: 'start-page' },
      h('header', { class: 'start-header' },
        h('h1', {}, 'devsurf'),
        h('p', { class: 'tagline', testid: 'tagline' }, 'Design developable surfaces together — strips, curved-crease folds, quad-mesh sheets and spline surfaces, bent from paper, sheet metal or plywood without stretching, or fitted to a shape you bring. Drag a point; the solver keeps the design developable, live for everyone in the session.')),
      // The three ways to start come first, in one row above the fold at 1280 × 720 however many
      // sessions are listed below them.
      h('div', { class: 'start-grid' },
        h('section', { class: 'card' }, h('h2', {}, 'New session from an example'),
          h('div', { class: 'row' }, this.presetSelect, this.newButton), this.presetDescription),
        this.blankSheet.root,
        h('section', { class: 'card' }, h('h2', {}, 'Open a scene or a crease pattern'), this.fileInput, this.dropZone,
          h('label', { class: 'row small' }, h('span', { class: 'muted' }, 'Crease pattern units'), this.importUnits),
          h('p', { class: 'muted small' }, 'A devsurf scene (format "devsurf-scene", version 1), or a crease pattern or folded form in FOLD format (.fold, as Origami Simulator and the FOLD tools write it), or a crease pattern drawn as SVG in Origami Simulator\'s colours (black outline, red mountain, blue valley; curves become curved creases). It becomes a new private session that the Fold slider folds.'),
          this.importNotes),
        this.mySessions,
        h('section', { class: 'card wide' }, h('h2', {}, 'Demo sessions'), h('p', { class: 'muted small' }, 'Public sessions anyone can join and edit.'), this.demoList),
        h('section', { class: 'card' }, h('h2', {}, 'Start from your own mesh'),
          h('p', { class: 'muted small' }, 'A triangle mesh with one boundary (.off, .obj, .ply, .stl) becomes developable patches glued along their borders, each with its flat cutting pattern (Jiang et al. 2020, §5). Solve it in the editor.'),
          this.meshInput,
          h('div', { class: 'row' }, h('label', { class: 'small' }, 'Patches ', this.meshPatches), h('label', { class: 'small' }, 'Quads ', this.meshFaces), this.meshButton)),
        h('section', { class: 'card wide', testid: 'shape-card' }, h('h2', {}, 'Fit strips to your own shape'),
          h('p', { class: 'muted small' }, 'Choose a region of a scan or mesh: one developable strip grows onto it while you watch (Tang et al. 2016 §4.2), or strips side by side become one composite covering it (Fig. 10) — or the whole shape, region by region.'),
          this.shapeInput, this.shapeInfo, this.regionView,
          h('div', { class: 'row' }, this.regionTool, this.centreField,
            h('label', { class: 'small' }, this.radiusName, this.regionRadius, ' ', this.regionRadiusLabel),
            this.regionCount, this.regionClear),
          this.regionHint,
          h('div', { class: 'row' }, this.regionMode, h('label', { class: 'small' }, 'Strips ', this.regionStrips), this.shapeRegionsField, this.keepOverField, this.regionButton)),
        h('section', { class: 'card' }, h('h2', {}, 'Join by link'),
          h('div', { class: 'row' }, this.joinInput, h('button', { class: 'btn', onclick: join }, 'Join')), this.joinError)),
      h('div', { class: 'start-status' }, this.apiKeyRow, this.busy, this.createError),
      h('footer', { class: 'start-footer muted small' }, 'devsurf — REST API at ', h('a', { href: 'api/openapi.json' }, '/api/openapi.json'), '. Press ? in the editor for shortcuts.'));
    root.appendChild(this.root);
    this._describePreset();
    this._bindDrop();
    this._showMySessions();
    this._loadDemos();
  }

  /** "Your sessions": every session this browser opened, its picture, edit and view links. */
  _showMySessions() {
    clear(this.mySessionList);
    const sessions = openedSessions();
    this.mySessions.hidden = sessions.length === 0;
    for (const s of sessions) {
      const token = s.edit || s.view;
      const when = new Date(s.opened);
      const gone = h('span', { class: 'field-error small', hidden: true }, 'no longer on this server');
      const links = [];
      if (s.edit) links.push(h('a', { class: 'small', testid: 'my-session-edit', href: editorUrl(s.id, s.edit) }, 'edit link'));
      if (s.view) links.push(h('a', { class: 'small', testid: 'my-session-view', href: editorUrl(s.id, s.view) }, 'view link'));
      const card = h('div', { class: 'demo-card', testid: 'my-session', dataset: { sessionId: s.id } },
        this.thumbnails.image(s.id, token, {
          alt: `${s.name || s.id}: the current surface`,
          onMissing: (e) => { if (e.status === 404) gone.hidden = false; },
        }),
        h('a', { class: 'demo-name', href: editorUrl(s.id, token), title: `Open “${s.name || s.id}”` }, s.name || s.id),
        h('span', { class: 'muted small' }, `${s.edit ? 'editing' : 'view only'} · opened ${when.toLocaleString()}`),
        gone,
        h('span', { class: 'demo-meta' }, ...links,
          h('button', { class: 'btn small', testid: 'forget-session', title: 'Remove from this list (the session itself stays)',
            onclick: () => { forgetSession(s.id); this._showMySessions(); } }, 'Forget')));
      this.mySessionList.appendChild(card);
    }
  }

  _describePreset() {
    const p = PRESETS.find((x) => x.id === this.presetSelect.value);
    this.presetSummary.textContent = p ? p.summary : '';
    this.presetDetailsText.textContent = p ? p.description : '';
  }

  async _loadDemos() {
    try {
      const sessions = await listSessions();
      clear(this.demoList);
      this.demoList.removeAttribute('aria-busy');
      if (!sessions.length) {
        this.demoList.appendChild(h('p', { class: 'muted' }, 'This server has no demo sessions (start it with --demo SCENE).'));
        return;
      }
      for (const s of sessions) {
        rememberSessionTokens(s.id, { edit: s.edit_token, view: s.view_token, name: s.name });
        const preset = PRESETS.find((p) => p.name === s.name);
        this.demoList.appendChild(h('a', { class: 'demo-card', testid: 'demo-session', dataset: { sessionId: s.id }, href: editorUrl(s.id, s.edit_token), title: `Open “${s.name}” for editing` },
          this.thumbnails.image(s.id, s.view_token, { alt: `${s.name || s.id}: the current surface` }),
          h('span', { class: 'demo-name' }, s.name || s.id),
          h('span', { class: 'muted small demo-desc', title: preset ? preset.description : '' }, preset ? preset.summary : s.id),
          h('span', { class: 'demo-meta' },
            h('span', { class: 'badge' }, `${s.participants} online`),
            h('span', { class: 'demo-view', role: 'link', tabindex: '0', title: 'Open read-only',
              onclick: (e) => { e.preventDefault(); e.stopPropagation(); window.location.assign(editorUrl(s.id, s.view_token)); } }, 'view only'))));
      }
    } catch (e) {
      clear(this.demoList);
      this.demoList.appendChild(h('p', { class: 'field-error' }, `Cannot list the sessions: ${e.message}`));
    }
  }

  _showCreateError(e, what) {
    if (e.status === 401) this.apiKeyRow.hidden = false;
    this.createError.textContent = `${what}: ${e.message}`;
    this.createError.hidden = false;
    this.toasts.showError({ code: e.code || 'error', message: e.message, path: e.path }, what);
  }

  /**
   * Opens a session on `scene`; `solved`: from its solved state (an example, as its picture shows
   * it). Resolves to true once the editor is being opened, false if the session was not made.
   */
  async _create(scene, what, { solved = false } = {}) {
    this.createError.hidden = true;
    this.toasts.hideError();
    this.busy.hidden = false;
    this.newButton.disabled = true;
    try {
      const res = await createSession(scene, this.apiKeyInput.value.trim() || apiKey(), { solved });
      rememberSessionTokens(res.id, { edit: res.edit_token, view: res.view_token, name: typeof scene === 'object' ? scene.name : undefined });
      window.location.assign(editorUrl(res.id, res.edit_token));
      return true;
    } catch (e) {
      this._showCreateError(e, what);
      return false;
    } finally {
      this.busy.hidden = true;
      this.newButton.disabled = false;
    }
  }

  async _approximateMesh() {
    const file = this.meshInput.files && this.meshInput.files[0];
    const what = file ? `approximate ${file.name}` : 'approximate a mesh';
    if (!file) {
      this._showCreateError({ message: 'choose a mesh file first', code: 'invalid', path: 'mesh' }, what);
      return;
    }
    const format = (file.name.split('.').pop() || '').toLowerCase();
    this.createError.hidden = true;
    this.busy.textContent = `Approximating ${file.name}…`;
    this.busy.hidden = false;
    this.meshButton.disabled = true;
    let result;
    try {
      result = await approximateMesh(file, {
        format,
        segments: Number(this.meshPatches.value) || 1,
        faces: Number(this.meshFaces.value) || 1500,
        name: `${file.name.replace(/\.[^.]*$/, '')} in developable patches`,
      }, this.apiKeyInput.value.trim() || apiKey());
    } catch (e) {
      this._showCreateError(e, what);
      this.busy.hidden = true;
      this.meshButton.disabled = false;
      return;
    } finally {
      this.busy.textContent = 'Creating the session…';
    }
    this.meshButton.disabled = false;
    await this._create(result.scene, what);
  }

  /** The shape file, its format, and a message when there is none. */
  _shapeFile() {
    const file = this.shapeInput.files && this.shapeInput.files[0];
    return file ? { file, format: (file.name.split('.').pop() || '').toLowerCase() } : null;
  }

  async _previewShape() {
    const shape = this._shapeFile();
    if (!shape) return;
    const what = `read ${shape.file.name}`;
    this.createError.hidden = true;
    this.regionButton.disabled = true;
    this.shapeInfo.textContent = `Reading ${shape.file.name}…`;
    try {
      this.preview = await previewShape(shape.file, { format: shape.format }, this.apiKeyInput.value.trim() || apiKey());
    } catch (e) {
      this.shapeInfo.textContent = `${shape.file.name} could not be read.`;
      this._showCreateError(e, what);
      return;
    }
    const p = this.preview;
    this.shapeInfo.textContent = `${shape.file.name}: ${p.points.toLocaleString('en')} points`
      + (p.triangles ? `, ${p.triangles.toLocaleString('en')} triangles` : '')
      + (p.shown < p.points ? ` (${p.shown.toLocaleString('en')} drawn)` : '') + '.';
    if (!this.regionPicker) {
      this.regionPicker = new RegionPicker({
        onPick: (c) => { this.regionCentre.value = c.map((v) => +v.toPrecision(6)).join(', '); this._updateRegion(); },
        onSelection: () => this._updateRegion(),
      });
      this.regionView.appendChild(this.regionPicker.element);
    }
    this.regionView.hidden = false;
    this.regionPicker.show(p);
    this._setRegionTool();
  }

  /** The region tool chosen: the ball takes a centre and a radius, the brush a radius, the lasso neither. */
  _setRegionTool() {
    const tool = this.regionTool.value;
    this.centreField.hidden = tool !== 'ball';
    this.radiusName.textContent = tool === 'brush' ? 'Brush radius ' : 'Radius ';
    this.regionRadius.closest('label').hidden = tool === 'lasso';
    this.regionClear.hidden = tool === 'ball';
    this.regionHint.textContent = {
      ball: 'Click the shape to centre the region; drag to turn the view, wheel to zoom.',
      brush: 'Paint the region with the left button (Shift erases); the right button turns the view.',
      lasso: 'Draw a loop around the region with the left button (Shift removes what it encloses); only the side facing you is taken. The right button turns the view.',
    }[tool];
    if (this.regionPicker) this.regionPicker.setTool(tool);
    this._updateRegion();
  }

  /** Whole-shape covers: at most ⌊200 / regions⌋ strips a region (the server's work bound). */
  _limitStrips() {
    if (this.regionMode.value !== 'whole') {
      this.regionStrips.max = '64';
      return;
    }
    const regions = Math.max(2, Math.min(32, Math.round(Number(this.shapeRegions.value) || 24)));
    const most = Math.max(1, Math.floor(200 / regions));
    this.regionStrips.max = String(most);
    if (Number(this.regionStrips.value) > most) this.regionStrips.value = String(most);
  }

  /** The centre typed or picked ([x, y, z] or null) and the radius in the shape's units. */
  _region() {
    const parts = this.regionCentre.value.split(/[\s,]+/).filter(Boolean).map(Number);
    const centre = parts.length === 3 && parts.every(Number.isFinite) ? parts : null;
    const radius = this.preview ? (Number(this.regionRadius.value) / 100) * this.preview.diagonal : 0;
    return { centre, radius };
  }

  _updateRegion() {
    if (this.pendingRegion) {
      this.pendingRegion = null;
      this.regionButton.textContent = 'Fit';
      this.createError.hidden = true;
    }
    const { centre, radius } = this._region();
    this.regionRadiusLabel.textContent = this.preview ? `${+radius.toPrecision(3)} (${this.regionRadius.value} %)` : `${this.regionRadius.value} %`;
    if (this.regionPicker) this.regionPicker.setRegion(centre, radius);
    const marked = this.regionPicker ? this.regionPicker.insideCount() : 0;
    this.regionCount.textContent = this.preview ? `${marked.toLocaleString('en')} points in the region` : '';
    // The whole shape needs no region; a ball needs its centre, a brush or lasso its points.
    const whole = this.regionMode.value === 'whole';
    this.regionButton.disabled = !this.preview || (!whole && (this.regionTool.value === 'ball' ? !centre : marked === 0));
    this.regionCentre.classList.toggle('invalid', this.regionCentre.value.trim() !== '' && !centre);
  }

  async _fitRegion() {
    // A result with warnings waits for a second click ("Open anyway").
    if (this.pendingRegion) {
      const { scene, what } = this.pendingRegion;
      this.pendingRegion = null;
      this.regionButton.textContent = 'Fit';
      await this._create(scene, what);
      return;
    }
    const shape = this._shapeFile();
    const { centre, radius } = this._region();
    const whole = this.regionMode.value === 'whole';
    const ball = this.regionTool.value === 'ball';
    if (!shape || (!whole && ball && !centre)) return;
    const cover = this.regionMode.value !== 'strip';
    const regions = whole ? Math.max(2, Math.min(32, Math.round(Number(this.shapeRegions.value) || 24))) : 1;
    const strips = Math.max(1, Math.min(whole ? Math.floor(200 / regions) : 64, Math.round(Number(this.regionStrips.value) || 4)));
    const stem = shape.file.name.replace(/\.[^.]*$/, '');
    const what = whole ? `cover ${shape.file.name}` : cover ? `cover a region of ${shape.file.name}` : `fit a strip to ${shape.file.name}`;
    this.createError.hidden = true;
    this.busy.textContent = whole ? `Covering ${regions} regions by ${strips} strips each…`
      : cover ? `Fitting ${strips} strips side by side…` : 'Placing the strip…';
    this.busy.hidden = false;
    this.regionButton.disabled = true;
    let result;
    try {
      const name = whole ? `${stem}: covered in ${regions} regions` : cover ? `${stem}: ${strips} strips` : `${stem}: fitted strip`;
      const overhang = !cover && this.keepOver.checked ? 0.001 : 0;
      const key = this.apiKeyInput.value.trim() || apiKey();
      // A painted or lassoed region goes as its own points (an XYZ cloud: the region is the whole
      // of it); the ball as the shape file with its centre and radius.
      result = whole
        ? await fitRegion(shape.file, { format: shape.format, centre: null, cover, strips, regions, name }, key)
        : ball
          ? await fitRegion(shape.file, { format: shape.format, centre, radius, cover, strips, overhang, name }, key)
          : await fitRegion(xyzBlob(this.regionPicker.selectedPositions()), { format: 'xyz', cover, strips, overhang, name }, key);
    } catch (e) {
      this._showCreateError(e, what);
      this.busy.hidden = true;
      this.regionButton.disabled = false;
      return;
    } finally {
      this.busy.textContent = 'Creating the session…';
    }
    this.busy.hidden = true;
    this.regionButton.disabled = false;
    const warnings = (result.summary && result.summary.warnings) || [];
    if (warnings.length) {
      const regions = whole && result.summary.regions;
      // A whole shape leaves some regions out as a rule: say how many, not every reason.
      this.createError.textContent = regions
        ? `${what}: ${result.summary.covered_regions} of ${regions.length} regions covered; ${warnings.length} warning${warnings.length === 1 ? '' : 's'}, e.g. ${warnings[0]}`
        : `${what}: ${warnings.join(' ')}`;
      this.createError.hidden = false;
      this.pendingRegion = { scene: result.scene, what };
      this.regionButton.textContent = 'Open anyway';
      return;
    }
    await this._create(result.scene, what);
  }

  _newFromPreset() {
    const p = PRESETS.find((x) => x.id === this.presetSelect.value);
    if (p) this._create(p.scene, `new session from ${p.file}`, { solved: true });
  }

  async _openFile(file) {
    const what = `open ${file.name}`;
    // The last import's notes and its "Open it" belong to that file, not to this one.
    this.importNotes.hidden = true;
    clear(this.importNotes);
    let text;
    try {
      text = await file.text();
    } catch (e) {
      this._showCreateError({ message: `cannot read the file (${e.message})`, code: 'read' }, what);
      return;
    }
    if (/\.svg$/i.test(file.name) || /^\s*(<\?xml[^>]*>\s*)?(<!--[\s\S]*?-->\s*)*(<!DOCTYPE[^>]*>\s*)?<svg[\s>]/i.test(text)) {
      await this._importCreasePattern(file, text, 'svg', { units: this.importUnits.value || undefined });
      return;
    }
    let scene;
    try {
      scene = JSON.parse(text);
    } catch (e) {
      this._showCreateError({ message: `not valid JSON (${e.message})`, code: 'invalid_json' }, what);
      return;
    }
    if (/\.fold$/i.test(file.name) || (scene && typeof scene === 'object' && !scene.format && Array.isArray(scene.vertices_coords))) {
      await this._importCreasePattern(file, text, 'fold', { units: this.importUnits.value || undefined });
      return;
    }
    // Neither a scene file nor a crease pattern: say what was expected (the schema's own word,
    // "format: is required", read as noise to a new user).
    if (!scene || typeof scene !== 'object' || Array.isArray(scene) || scene.format === undefined) {
      this._showCreateError({ message: `${file.name} is neither a devsurf scene file (its "format" is "devsurf-scene") nor a FOLD crease pattern (with vertices_coords), nor an SVG drawing`, code: 'invalid' }, what);
      return;
    }
    // The server validates against the scene schema and names the offending field.
    this._create(scene, what);
  }

  /**
   * A FOLD file or SVG drawing → a composite scene (POST /api/imports). Without notes (or with
   * `openAtOnce`) its session opens at once; with notes they are listed first, with a button to
   * open the session. `units`: the scene units of the file's numbers (the import's parameter;
   * absent: the file's own). Resolves to true when the editor is being opened.
   */
  async _importCreasePattern(file, text, format = 'fold', { openAtOnce = false, units } = {}) {
    const what = `import ${file.name}`;
    this.createError.hidden = true;
    this.toasts.hideError();  // an earlier file's error would cover this one's notes and "Open it"
    this.importNotes.hidden = true;
    clear(this.importNotes);
    this.busy.textContent = `Importing ${file.name}…`;
    this.busy.hidden = false;
    let result;
    try {
      result = await importCreasePattern(text, { format, name: file.name.replace(/\.[^.]*$/, ''), units }, this.apiKeyInput.value.trim() || apiKey());
    } catch (e) {
      this._showCreateError(e, what);
      return false;
    } finally {
      this.busy.hidden = true;
      this.busy.textContent = 'Creating the session…';
    }
    const notes = (result.summary && result.summary.notes) || [];
    if (notes.length === 0 || openAtOnce) return this._create(result.scene, what);
    const s = result.summary;
    this.importNotes.append(
      h('p', { class: 'small' }, `${file.name}: ${s.faces} faces; crease edges ${s.edges.mountain} mountain and ${s.edges.valley} valley${s.curved_creases ? ` (${s.curved_creases} curved ${s.curved_creases === 1 ? 'crease' : 'creases'} among them, each in several edges)` : ''}${s.folded_state ? ', in its folded form' : ', flat'}. The import noted:`),
      h('ul', { class: 'small' }, ...notes.map((n) => h('li', { testid: 'import-note' }, h('span', { class: 'mono' }, n.element), `: ${n.message}`))),
      h('button', { class: 'btn primary', testid: 'open-imported', onclick: () => this._create(result.scene, what) }, 'Open it'));
    this.importNotes.hidden = false;
    return false;
  }

  _bindDrop() {
    const page = document.documentElement;
    let depth = 0;
    page.addEventListener('dragenter', (e) => {
      if (!e.dataTransfer || ![...e.dataTransfer.types].includes('Files')) return;
      depth++;
      this.root.classList.add('dragging-file');
    });
    page.addEventListener('dragleave', () => {
      depth = Math.max(0, depth - 1);
      if (depth === 0) this.root.classList.remove('dragging-file');
    });
    page.addEventListener('dragover', (e) => {
      if (e.dataTransfer && [...e.dataTransfer.types].includes('Files')) {
        e.preventDefault();
        e.dataTransfer.dropEffect = 'copy';
      }
    });
    page.addEventListener('drop', (e) => {
      const f = e.dataTransfer && e.dataTransfer.files && e.dataTransfer.files[0];
      depth = 0;
      this.root.classList.remove('dragging-file');
      if (!f) return;
      e.preventDefault();
      this._openFile(f);
    });
  }
}
