// Entry point: the start page at `/`, the editor at `/?session=ID&token=TOKEN`.
// window.__devsurf is the test hook described in CONTRACT.md.

import './styles.css';
import { EditorState } from './state/EditorState.js';
import { accessibility, displayName } from './ui/preferences.js';
import { defaultSocketUrl, openEarlyJoin } from './net/ProtocolClient.js';

const state = new EditorState();
let editor = null;
let startPage = null;

window.__devsurf = {
  state,
  controlPointScreenPosition(curve, index) {
    return editor ? editor.controlPointScreenPosition(curve, index) : null;
  },
  /** Composites too: a target {curve, index}, {vertex} or {edge, index}. */
  pointScreenPosition(target) {
    return editor ? editor.pointScreenPosition(target) : null;
  },
  /** The selection marker (diamond) of a composite's edge. */
  edgeScreenPosition(edge) {
    return editor ? editor.edgeScreenPosition(edge) : null;
  },
  /** quad_mesh: CSS px position of vertex i of M′ relative to the unfolding view (unfolding-view). */
  unfoldingScreenPosition(vertex) {
    return editor ? editor.unfolding.vertexScreenPosition(vertex) : null;
  },
  /** Composites with a drawing: client (page) px of sheet point [x, y] on the open crease board. */
  creaseBoardPoint(p) {
    return editor ? editor.creaseBoard.clientPoint(p) : null;
  },
  iterateApplyTimes() {
    return editor ? editor.applyTimes.slice() : [];
  },
  get editor() {
    return editor;
  },
  /** The start page (its region picker: tests read the marked region back). */
  get startPage() {
    return startPage;
  },
};

const root = document.getElementById('app');
document.documentElement.classList.toggle('a11y', accessibility());
const params = new URLSearchParams(window.location.search);
const session = params.get('session');
const token = params.get('token');
// Each page loads only its own code (separate chunks): the editor does not wait for the start
// page's bundled example scenes (~1 MB), the start page not for the editor's views and panels.
if (session && token) {
  document.body.classList.add('editor-page');
  // The WebSocket handshake and the join run while the editor's code loads; the editor takes the
  // connection over with the answers that came meanwhile (the session's state).
  let socket = null;
  try {
    socket = openEarlyJoin(defaultSocketUrl(), session, token, displayName());
  } catch { /* the editor opens its own */ }
  const { Editor } = await import('./ui/Editor.js');
  performance.mark('devsurf:editor-code');
  editor = new Editor(root, { state, session, token, socket });
  performance.mark('devsurf:editor-built');
} else {
  document.body.classList.add('start');
  const { StartPage } = await import('./ui/StartPage.js');
  startPage = new StartPage(root, { state });
}
