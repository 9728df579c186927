// Exact input while dragging (issue 16, item 4): a drag may be held to an axis or a plane through
// the point where it started, and its position snapped to a grid. Pure functions of plain arrays,
// shared by the 3D view's pointer handling and the unit tests.

/** The constraints a drag can have: the view plane (free), an axis, or a coordinate plane. */
export const DRAG_CONSTRAINTS = ['free', 'x', 'y', 'z', 'xy', 'yz', 'zx'];

const AXES = { x: [1, 0, 0], y: [0, 1, 0], z: [0, 0, 1] };
/** A coordinate plane by its normal. */
const PLANE_NORMALS = { xy: [0, 0, 1], yz: [1, 0, 0], zx: [0, 1, 0] };
/** The coordinates a constraint leaves free (the ones snapping rounds). */
const FREE_COORDINATES = { free: [0, 1, 2], x: [0], y: [1], z: [2], xy: [0, 1], yz: [1, 2], zx: [2, 0] };

const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
const sub = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
const add = (a, b, s = 1) => [a[0] + s * b[0], a[1] + s * b[1], a[2] + s * b[2]];

/**
 * Where a drag is, given the pointer's ray.
 * @param {number[]} start       the dragged point when the drag began, [x, y, z]
 * @param {number[]} free        the unconstrained position (on the view plane through start)
 * @param {{origin: number[], direction: number[]}} ray  the pointer's ray (direction unit length)
 * @param {{constraint?: string, snap?: boolean, step?: number}} options
 * @returns {number[]} the position to send, [x, y, z]
 */
export function constrainedDragPosition(start, free, ray, { constraint = 'free', snap = false, step = 0 } = {}) {
  let p = free.slice();
  if (AXES[constraint]) {
    // The point of the axis line nearest to the ray (closest points of two lines).
    const e = AXES[constraint];
    const d = ray.direction;
    const w = sub(ray.origin, start);
    const ed = dot(e, d);
    const denominator = 1 - ed * ed;
    const t = denominator < 1e-6 ? dot(sub(free, start), e) : (dot(w, e) - ed * dot(w, d)) / denominator;
    p = add(start, e, t);
  } else if (PLANE_NORMALS[constraint]) {
    const n = PLANE_NORMALS[constraint];
    const dn = dot(ray.direction, n);
    if (Math.abs(dn) > 1e-6) {
      const t = dot(sub(start, ray.origin), n) / dn;
      p = add(ray.origin, ray.direction, t);
    } else {
      p = add(free, n, -dot(sub(free, start), n));  // seen edge-on: the free position, onto the plane
    }
  }
  if (snap && step > 0) {
    for (const k of FREE_COORDINATES[constraint] || FREE_COORDINATES.free) p[k] = Math.round(p[k] / step) * step;
  }
  return p.map((x) => (Object.is(x, -0) ? 0 : x));
}

/**
 * A grid step for a design of this size (its diagonal): 1, 2 or 5 × a power of ten, the one
 * nearest (by ratio) to a fiftieth of it — 250 → 5, 3162 → 50 — so a design a little larger or
 * smaller keeps its step.
 */
export function defaultGridStep(size) {
  if (!(size > 0) || !Number.isFinite(size)) return 1;
  const raw = size / 50;
  const power = 10 ** Math.floor(Math.log10(raw));
  let best = power;
  for (const m of [2, 5, 10]) {
    const step = m * power;
    if (Math.max(step / raw, raw / step) < Math.max(best / raw, raw / best)) best = step;
  }
  return Number(best.toPrecision(1));
}
