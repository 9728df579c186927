// Start page: demo sessions, new session from a bundled preset, open a scene file (input or
// drag-and-drop anywhere on the page), join by link.

import { h, clear } from './dom.js';
import { PRESETS } from '../presets.js';
import { approximateMesh, createSession, listSessions } from '../net/api.js';
import { Toasts } from './Toast.js';
import { apiKey, rememberSessionTokens, setApiKey } from './preferences.js';

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

export class StartPage {
  constructor(root, { state }) {
    this.state = state;
    this.toasts = new Toasts(document.body);
    this.demoList = h('div', { class: 'demo-list', 'aria-busy': 'true' }, h('p', { class: 'muted' }, 'Loading demo sessions…'));

    this.presetSelect = h('select', { class: 'input', testid: 'preset-select', 'aria-label': 'Example scene' },
      PRESETS.map((p) => h('option', { value: p.id }, p.name)));
    this.presetDescription = h('p', { class: 'muted small preset-description' });
    this.presetSelect.addEventListener('change', () => this._describePreset());
    this.newButton = h('button', { class: 'btn primary', testid: 'new-session', onclick: () => this._newFromPreset() }, 'New session');

    this.fileInput = h('input', { type: 'file', accept: '.json,application/json', testid: 'scene-file', class: 'file-input', id: 'scene-file' });
    this.fileInput.addEventListener('change', () => {
      const f = this.fileInput.files && this.fileInput.files[0];
      if (f) this._openFile(f);
    });
    this.dropZone = h('label', { class: 'drop-zone', for: 'scene-file' },
      h('strong', {}, 'Choose a scene file'), h('span', { class: 'muted' }, ' or drop a .json file anywhere on this page'));

    // A user's own mesh → glued developable patches (POST /api/approximations), opened as a session.
    this.meshInput = h('input', { type: 'file', accept: '.off,.obj,.ply,.stl', testid: 'mesh-file', class: 'input', 'aria-label': 'Mesh file' });
    this.meshPatches = h('input', { type: 'number', class: 'input narrow', min: '1', max: '1000', value: '8', testid: 'mesh-patches', 'aria-label': 'Patches' });
    this.meshFaces = h('input', { type: 'number', class: 'input narrow', min: '4', max: '100000', value: '1500', testid: 'mesh-faces', 'aria-label': 'Quads' });
    this.meshButton = h('button', { class: 'btn', testid: 'approximate-mesh', onclick: () => this._approximateMesh() }, 'Approximate');

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

    this.root = h('div', { class: 'start-page', testid: 'start-page' },
      h('header', { class: 'start-header' },
        h('h1', {}, 'devsurf'),
        h('p', { class: 'tagline' }, 'Design developable strips together — surfaces bent from sheet material without stretching. Drag the control points; the solver keeps the strip developable, live for everyone in the session.')),
      h('div', { class: 'start-grid' },
        h('section', { class: 'card wide' }, h('h2', {}, 'Demo sessions'), h('p', { class: 'muted small' }, 'Public sessions anyone can join and edit.'), this.demoList),
        h('section', { class: 'card' }, h('h2', {}, 'New session from an example'),
          h('div', { class: 'row' }, this.presetSelect, this.newButton), this.presetDescription),
        h('section', { class: 'card' }, h('h2', {}, 'Open a scene file'), this.fileInput, this.dropZone,
          h('p', { class: 'muted small' }, 'A devsurf scene (format "devsurf-scene", version 1). It becomes a new private session.')),
        h('section', { class: 'card' }, h('h2', {}, 'Start from your own mesh'),
          h('p', { class: 'muted small' }, 'A triangle mesh with one boundary (.off, .obj, .ply, .stl) becomes developable patches glued along their borders, each with its flat cutting pattern (Jiang et al. 2020, §5). Solve it in the editor.'),
          this.meshInput,
          h('div', { class: 'row' }, h('label', { class: 'small' }, 'Patches ', this.meshPatches), h('label', { class: 'small' }, 'Quads ', this.meshFaces), this.meshButton)),
        h('section', { class: 'card' }, h('h2', {}, 'Join by link'),
          h('div', { class: 'row' }, this.joinInput, h('button', { class: 'btn', onclick: join }, 'Join')), this.joinError)),
      h('div', { class: 'start-status' }, this.apiKeyRow, this.busy, this.createError),
      h('footer', { class: 'start-footer muted small' }, 'devsurf — REST API at ', h('a', { href: 'api/openapi.json' }, '/api/openapi.json'), '. Press ? in the editor for shortcuts.'));
    root.appendChild(this.root);
    this._describePreset();
    this._bindDrop();
    this._loadDemos();
  }

  _describePreset() {
    const p = PRESETS.find((x) => x.id === this.presetSelect.value);
    this.presetDescription.textContent = p ? p.description : '';
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
          h('span', { class: 'demo-name' }, s.name || s.id),
          h('span', { class: 'muted small demo-desc' }, preset ? preset.description : s.id),
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

  async _create(scene, what) {
    this.createError.hidden = true;
    this.busy.hidden = false;
    this.newButton.disabled = true;
    try {
      const res = await createSession(scene, this.apiKeyInput.value.trim() || apiKey());
      rememberSessionTokens(res.id, { edit: res.edit_token, view: res.view_token, name: typeof scene === 'object' ? scene.name : undefined });
      window.location.assign(editorUrl(res.id, res.edit_token));
    } catch (e) {
      this._showCreateError(e, what);
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

  _newFromPreset() {
    const p = PRESETS.find((x) => x.id === this.presetSelect.value);
    if (p) this._create(p.scene, `new session from ${p.file}`);
  }

  async _openFile(file) {
    const what = `open ${file.name}`;
    let text;
    try {
      text = await file.text();
    } catch (e) {
      this._showCreateError({ message: `cannot read the file (${e.message})`, code: 'read' }, what);
      return;
    }
    let scene;
    try {
      scene = JSON.parse(text);
    } catch (e) {
      this._showCreateError({ message: `not valid JSON (${e.message})`, code: 'invalid_json' }, what);
      return;
    }
    // The server validates against the scene schema and names the offending field.
    this._create(scene, what);
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
