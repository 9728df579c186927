// "Start from a blank sheet" (start page): a rectangle outline as an SVG crease pattern, imported
// like a dropped SVG file (with the sheet's unit as the import's `units`), so the editor opens on
// a flat sheet with its drawing, in the unit chosen, ready to draw creases on.

import { h } from './dom.js';

export const BLANK_UNITS = ['mm', 'cm', 'm', 'in'];
export const BLANK_DEFAULT = { width: 200, height: 150, units: 'mm' };
/** Largest side accepted, in millimetres (100 m). */
const MAX_SIDE_MM = 1e5;
const MM_PER = { mm: 1, cm: 10, m: 1000, in: 25.4 };

/** A number as SVG text: up to 6 significant digits, no exponent for ordinary sizes. */
function num(x) {
  return String(Number(x.toPrecision(6)));
}

/** Checks a blank sheet's size; the error names the field. */
export function checkBlankSheet(width, height, units) {
  if (!BLANK_UNITS.includes(units)) throw new TypeError(`units: expected one of ${BLANK_UNITS.join(', ')}`);
  for (const [name, v] of [['width', width], ['height', height]]) {
    if (typeof v !== 'number' || !Number.isFinite(v) || v <= 0) throw new TypeError(`${name}: enter a size greater than 0`);
    if (v * MM_PER[units] > MAX_SIDE_MM) throw new TypeError(`${name}: at most ${num(MAX_SIDE_MM / MM_PER[units])} ${units}`);
  }
}

/**
 * The SVG text of a blank sheet: a black rectangle outline of width × height `units`, its numbers
 * as typed in the viewBox, its width and height in that unit (metres as millimetres: SVG has no
 * "m"). The import is told `units` (blankSheetImport) and converts the drawing's size to them
 * (POST /api/imports: a file that states its units is converted), so a 20 × 15 cm sheet is a
 * scene in cm, 20 × 15.
 */
export function blankSheetSvg(width, height, units = 'mm') {
  checkBlankSheet(width, height, units);
  const w = num(width);
  const ht = num(height);
  // Stroke width: a thin line, ~0.5 mm on the sheet.
  const sw = num(Math.min(0.5 / MM_PER[units], Math.min(width, height) / 100));
  const size = (v) => (units === 'm' ? `${num(v * 1000)}mm` : `${num(v)}${units}`);
  return `<svg xmlns="http://www.w3.org/2000/svg" width="${size(width)}" height="${size(height)}" viewBox="0 0 ${w} ${ht}">\n`
    + `  <rect x="0" y="0" width="${w}" height="${ht}" fill="none" stroke="#000" stroke-width="${sw}"/>\n`
    + '</svg>\n';
}

/**
 * What the start page imports for a blank sheet: {svg, name, units} — the SVG of its outline, the
 * session's name, and the scene units the import gives the drawing's numbers.
 */
export function blankSheetImport(width, height, units) {
  return { svg: blankSheetSvg(width, height, units), name: blankSheetName(width, height, units), units };
}

/** The session name of a blank sheet: "Blank sheet 200 × 150 mm". */
export function blankSheetName(width, height, units) {
  return `Blank sheet ${num(width)} × ${num(height)} ${units}`;
}

/**
 * The start page's card: width, height, units and a button; `create({svg, name, units})` imports it and
 * resolves to true when the editor is being opened: the button is disabled and says "Creating…"
 * from the click on, and is given back only if the sheet was not made.
 * Returns {root, error (element for messages), button}.
 */
export function blankSheetCard(create) {
  const width = h('input', { type: 'number', class: 'input narrow', min: '0', step: 'any', value: String(BLANK_DEFAULT.width), testid: 'blank-width', 'aria-label': 'Sheet width' });
  const height = h('input', { type: 'number', class: 'input narrow', min: '0', step: 'any', value: String(BLANK_DEFAULT.height), testid: 'blank-height', 'aria-label': 'Sheet height' });
  const units = h('select', { class: 'input fit', testid: 'blank-units', 'aria-label': 'Units' },
    BLANK_UNITS.map((u) => h('option', { value: u, selected: u === BLANK_DEFAULT.units }, u)));
  const error = h('div', { class: 'field-error', hidden: true, role: 'alert' });
  let button;
  const go = async () => {
    if (button.disabled) return;  // one sheet per click, even while the import takes its time
    const w = Number(width.value);
    const ht = Number(height.value);
    let sheet;
    try {
      sheet = blankSheetImport(w, ht, units.value);
    } catch (e) {
      error.textContent = e.message;
      error.hidden = false;
      return;
    }
    error.hidden = true;
    // The start page's own busy line is at its foot, out of sight at 1280 × 720: the button says
    // what is happening where it was clicked, until the editor opens (or an error is shown).
    // It stays so while the browser opens the editor (create resolves true): a click in that
    // gap would make a second sheet and leave the first behind.
    button.disabled = true;
    button.textContent = 'Creating…';
    button.setAttribute('aria-busy', 'true');
    let opening = false;
    try {
      opening = (await create(sheet)) === true;
    } finally {
      if (!opening) {
        button.disabled = false;
        button.textContent = 'Start drawing';
        button.removeAttribute('aria-busy');
      }
    }
  };
  for (const input of [width, height]) input.addEventListener('keydown', (e) => { if (e.key === 'Enter') go(); });
  button = h('button', { class: 'btn primary', testid: 'blank-sheet', onclick: go }, 'Start drawing');
  const root = h('section', { class: 'card', testid: 'blank-sheet-card' },
    h('h2', {}, 'Start from a blank sheet'),
    h('div', { class: 'row blank-size' },
      h('label', { class: 'small' }, 'W ', width), h('span', { class: 'muted' }, '×'),
      h('label', { class: 'small' }, 'H ', height), units, button),
    error,
    h('p', { class: 'muted small' }, 'A flat rectangular sheet: draw its creases (straight or curved, mountain or valley) on the crease-pattern board, then fold it with the Fold slider.'));
  return { root, error, button };
}
