import { h } from './dom.js';

const SHORTCUTS = [
  ['Drag a control point', 'pull it; the solver follows live (view-plane drag)'],
  ['Drag elsewhere / wheel', 'orbit / zoom (right button: pan)'],
  ['Click', 'select a control point (others see it in your colour)'],
  ['F', 'fix / unfix the selected point'],
  ['H', 'add / remove a handle at the selected point'],
  ['Shift+click / Ctrl+click', 'composites: add a point to / remove it from the group selection (white rings; Esc clears it, a plain click selects one point again)'],
  ['R / Shift+R', 'composites: turn the group about the axis of the Selection panel by its angle (Shift: the other way), then solve'],
  ['G', 'quad meshes: glue mode — click two boundary vertices (in M or M′) to glue them'],
  ['S', 'solve until every constraint is met (within 2 s)'],
  ['Ctrl+Z', 'undo (the session’s shared history)'],
  ['Ctrl+Shift+Z / Ctrl+Y', 'redo'],
  ['Space', 'fit the view'],
  ['Ctrl+S', 'save the scene file'],
  ['Draw creases', 'composites made from a drawing (a blank sheet, an SVG or FOLD import): the crease-pattern board — Line (click two ends), Curve (click points; double-click or Enter finishes, Backspace undoes a point), Select (relabel M V F C, drag points, double-click adds one, Alt-click removes one, Delete erases); points snap to creases within 10 px'],
  ['Esc', 'clear the selection / close this help (on the board: cancel, deselect, close)'],
  ['?', 'show / hide this help'],
];

export class HelpOverlay {
  constructor(parent) {
    this.root = h('div', { class: 'overlay', testid: 'help-overlay', hidden: true, role: 'dialog', 'aria-modal': 'true', 'aria-label': 'Keyboard shortcuts',
      onclick: (e) => { if (e.target === this.root) this.hide(); } },
    h('div', { class: 'overlay-card' },
      h('h2', {}, 'Keyboard and mouse'),
      h('table', { class: 'shortcuts' },
        SHORTCUTS.map(([k, d]) => h('tr', {}, h('th', {}, h('kbd', {}, k)), h('td', {}, d)))),
      h('p', { class: 'muted' }, 'Colours: the surface is shaded by the measure the legend names — warp angle on strips (0° = developable), face flatness on composites, the chosen measure on quad meshes. Cubes are fixed points, magenta points have a handle (its target is the wire diamond). Composites: the Fold panel folds the sheet from flat (0 %) to the design (100 %).'),
      h('button', { class: 'btn', onclick: () => this.hide() }, 'Close')));
    parent.appendChild(this.root);
  }

  get visible() {
    return !this.root.hidden;
  }

  toggle() {
    this.root.hidden = !this.root.hidden;
  }

  hide() {
    this.root.hidden = true;
  }
}
