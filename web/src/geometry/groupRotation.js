// Turning a group of a composite's points (rotate_points, 000_… §4.1 Fig. 8): the axis of a name,
// the centroid, the turn itself (the server's: right hand, degrees) and the Selection panel's
// inputs read into a RotatePointsCommand. No DOM, no three.js: unit-tested in web/test.

import { RotatePointsCommand, ROTATE_ANGLE_MAX, ROTATE_ITERATIONS_MAX } from '../commands/RotatePointsCommand.js';

/** Axis buttons of the Selection panel: the coordinate axes, and the viewing direction. */
export const ROTATE_AXES = ['x', 'y', 'z', 'view'];
export const DEFAULT_ROTATE_ANGLE = 15;

const UNIT = { x: [1, 0, 0], y: [0, 1, 0], z: [0, 0, 1] };

/**
 * The axis vector of a button: x, y, z; 'view' points from the model towards the viewer (minus
 * the camera's viewing direction), so that a positive angle turns counter-clockwise on screen.
 * Null when 'view' has no usable direction.
 */
export function axisVector(name, viewDirection) {
  if (UNIT[name]) return UNIT[name].slice();
  if (name !== 'view' || !viewDirection) return null;
  const d = [0, 1, 2].map((k) => -Number(viewDirection[k]));
  const n = Math.hypot(...d);
  return Number.isFinite(n) && n > 1e-12 ? d.map((x) => x / n) : null;
}

/** The centroid of points ([x, y, z]; null entries skipped), or null when there is none. */
export function centroid(points) {
  const list = points.filter((p) => p && p.length === 3);
  if (!list.length) return null;
  const c = [0, 0, 0];
  for (const p of list) for (let k = 0; k < 3; k++) c[k] += Number(p[k]) / list.length;
  return c;
}

/** p turned by `degrees` about the axis through `centre` (Rodrigues; right hand). */
export function rotatePoint(p, centre, axis, degrees) {
  const n = Math.hypot(axis[0], axis[1], axis[2]);
  const k = [axis[0] / n, axis[1] / n, axis[2] / n];
  const v = [p[0] - centre[0], p[1] - centre[1], p[2] - centre[2]];
  const a = (degrees * Math.PI) / 180;
  const c = Math.cos(a);
  const s = Math.sin(a);
  const dot = k[0] * v[0] + k[1] * v[1] + k[2] * v[2];
  const cross = [k[1] * v[2] - k[2] * v[1], k[2] * v[0] - k[0] * v[2], k[0] * v[1] - k[1] * v[0]];
  return [0, 1, 2].map((i) => centre[i] + v[i] * c + cross[i] * s + k[i] * dot * (1 - c));
}

/**
 * The signed angle (degrees, right hand about `axis`) from p to q as seen down the axis through
 * `centre`: how far a point turned. NaN when either lies on the axis.
 */
export function turnAngle(p, q, centre, axis) {
  const n = Math.hypot(axis[0], axis[1], axis[2]);
  const k = axis.map((x) => x / n);
  const flat = (x) => {
    const v = [0, 1, 2].map((i) => x[i] - centre[i]);
    const d = v[0] * k[0] + v[1] * k[1] + v[2] * k[2];
    return v.map((vi, i) => vi - d * k[i]);
  };
  const a = flat(p);
  const b = flat(q);
  if (Math.hypot(...a) < 1e-12 || Math.hypot(...b) < 1e-12) return NaN;
  const cross = [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
  const sin = cross[0] * k[0] + cross[1] * k[1] + cross[2] * k[2];
  const cos = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
  return (Math.atan2(sin, cos) * 180) / Math.PI;
}

const blank = (text) => text === undefined || text === null || String(text).trim() === '';

/**
 * The Selection panel's rotate inputs as a command, or {error: {field, message}}.
 * @param {object} input {targets, axis: 'x'|'y'|'z'|'view', viewDirection, angle (text),
 *   centre: [text ×3] or null (blank: the server's centroid), iterations (text; blank: default),
 *   source}
 */
export function rotateCommandFrom({ targets, axis, viewDirection, angle, centre, iterations, source }) {
  if (!targets || !targets.length) return { error: { field: 'targets', message: 'select points first (Shift+click adds one)' } };
  const a = axisVector(axis, viewDirection);
  if (!a) return { error: { field: 'axis', message: 'choose an axis: X, Y, Z or the viewing direction' } };
  const degrees = Number(angle);
  if (blank(angle) || !Number.isFinite(degrees) || Math.abs(degrees) > ROTATE_ANGLE_MAX) {
    return { error: { field: 'angle', message: `angle: enter degrees in [−${ROTATE_ANGLE_MAX}, ${ROTATE_ANGLE_MAX}]` } };
  }
  const options = { source };
  if (centre && !centre.every(blank)) {
    const c = centre.map(Number);
    const bad = centre.findIndex((text, k) => blank(text) || !Number.isFinite(c[k]));
    if (bad >= 0) return { error: { field: 'centre', message: `centre ${'xyz'[bad]}: enter a number` } };
    options.centre = c;
  }
  if (!blank(iterations)) {
    const n = Number(iterations);
    if (!Number.isInteger(n) || n < 0 || n > ROTATE_ITERATIONS_MAX) {
      return { error: { field: 'iterations', message: `solve: enter 0 … ${ROTATE_ITERATIONS_MAX} iterations (blank: the session's)` } };
    }
    options.iterations = n;
  }
  try {
    return { command: new RotatePointsCommand(targets, a, degrees, options) };
  } catch (e) {
    return { error: { field: String(e.message).split(':')[0], message: e.message } };
  }
}
