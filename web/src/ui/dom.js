// Tiny DOM helpers.

/**
 * h('button', {class: 'x', testid: 'y', onclick: fn, dataset: {...}}, 'text', child, …)
 * Attributes: class, testid (→ data-testid), dataset, style (object or string), on* handlers,
 * boolean attributes (true → present, false/null/undefined → absent), others via setAttribute.
 */
export function h(tag, attrs = {}, ...children) {
  const el = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs || {})) {
    if (v === undefined || v === null || v === false) continue;
    if (k === 'class') el.className = v;
    else if (k === 'testid') el.dataset.testid = v;
    else if (k === 'dataset') Object.assign(el.dataset, v);
    else if (k === 'style' && typeof v === 'object') Object.assign(el.style, v);
    else if (k.startsWith('on') && typeof v === 'function') el.addEventListener(k.slice(2), v);
    else if (k === 'value') el.value = v;
    else if (k === 'text') el.textContent = v;
    else if (v === true) el.setAttribute(k, '');
    else el.setAttribute(k, String(v));
  }
  append(el, children);
  return el;
}

function append(el, children) {
  for (const c of children) {
    if (c === null || c === undefined || c === false) continue;
    if (Array.isArray(c)) append(el, c);
    else el.appendChild(c instanceof Node ? c : document.createTextNode(String(c)));
  }
}

export function clear(el) {
  while (el.firstChild) el.removeChild(el.firstChild);
  return el;
}

/** Saves a Blob (or text) as a file download. */
export function download(blobOrText, filename, type = 'application/octet-stream') {
  const blob = blobOrText instanceof Blob ? blobOrText : new Blob([blobOrText], { type });
  const url = URL.createObjectURL(blob);
  const a = h('a', { href: url, download: filename, style: { display: 'none' } });
  document.body.appendChild(a);
  a.click();
  setTimeout(() => {
    URL.revokeObjectURL(url);
    a.remove();
  }, 1000);
}

/** Copies text to the clipboard (falls back to a selected input and execCommand). */
export async function copyText(text, input) {
  try {
    if (navigator.clipboard && window.isSecureContext) {
      await navigator.clipboard.writeText(text);
      return true;
    }
  } catch {
    /* fall through */
  }
  if (input) {
    input.focus();
    input.select();
    try {
      return document.execCommand('copy');
    } catch {
      return false;
    }
  }
  return false;
}

/** A short file-name-safe version of a name. */
export function slug(name, fallback = 'devsurf') {
  const s = String(name || '').toLowerCase().replace(/[^a-z0-9]+/g, '-').replace(/^-+|-+$/g, '').slice(0, 60);
  return s || fallback;
}

/**
 * Numbers smaller than this in magnitude are shown as 0: a metric or residual this small has
 * reached zero up to rounding (the solver's denormals, 6.3e-321), it is not a measurement.
 */
export const NEGLIGIBLE_MAGNITUDE = 1e-300;

/** Formats a number for display: fixed for ordinary values, exponential for tiny ones, 0 for negligible ones. */
export function formatNumber(v, digits = 3) {
  if (typeof v !== 'number' || !Number.isFinite(v)) return '–';
  const a = Math.abs(v);
  if (a < NEGLIGIBLE_MAGNITUDE) return '0';
  if (a >= 0.01 && a < 1e5) return formatFixed(v, digits);
  return v.toExponential(2);
}

/** x in exponent notation with `digits` decimals ('6.30e-5'); '0' for 0 and negligible values. */
export function formatExponential(x, digits = 2) {
  if (typeof x !== 'number' || !Number.isFinite(x)) return '–';
  if (Math.abs(x) < NEGLIGIBLE_MAGNITUDE) return '0';
  return x.toExponential(digits);
}

/** x to `digits` significant digits, no trailing zeros ('0.0931', '4e-7'); '0' for negligible values. */
export function formatSignificant(x, digits = 3) {
  if (typeof x !== 'number' || !Number.isFinite(x)) return '–';
  if (Math.abs(x) < NEGLIGIBLE_MAGNITUDE) return '0';
  return String(Number(x.toPrecision(digits)));
}

/** x with `digits` decimals; a value that rounds to zero has no minus sign ('0.000', not '-0.000'). */
export function formatFixed(x, digits = 3) {
  if (typeof x !== 'number' || !Number.isFinite(x)) return '–';
  const text = x.toFixed(digits);
  return Number(text) === 0 ? (0).toFixed(digits) : text;
}
