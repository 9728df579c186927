import { Command, target } from './Command.js';

/** At most this many points turn in one rotate_points message (the schema's maxItems). */
export const ROTATE_TARGETS_MAX = 10000;
/** |angle| ≤ this many degrees. */
export const ROTATE_ANGLE_MAX = 360;
/** Solver iterations after the turn: 0 … this (default: the session's release iterations). */
export const ROTATE_ITERATIONS_MAX = 1000;

/** A composite's point: a vertex {vertex} or control point `index` of an S edge {edge, index}. */
function compositeTarget(t, k) {
  let x;
  try {
    x = target(t);
  } catch {
    x = null;
  }
  if (!x || x.curve !== undefined || x.on !== undefined) {
    throw new TypeError(`targets[${k}]: expected a composite's point {vertex} or {edge, index}, got ${JSON.stringify(t)}`);
  }
  return x;
}

function vector3(v, name) {
  if (!v || typeof v.length !== 'number' || v.length !== 3) throw new TypeError(`${name}: expected 3 numbers`);
  const out = [Number(v[0]), Number(v[1]), Number(v[2])];
  if (!out.every(Number.isFinite)) throw new TypeError(`${name}: expected 3 finite numbers`);
  return out;
}

/**
 * Composite sessions: turn a group of points rigidly about an axis through `centre` (default: the
 * server takes their centroid) by `angle` degrees, counter-clockwise looking down the axis (right
 * hand), then solve (`iterations`; default the session's release iterations). One undo step
 * (000_… §4.1, Fig. 8 bottom row).
 */
export class RotatePointsCommand extends Command {
  /**
   * @param {object[]} targets  composite points ({vertex} | {edge, index}), 1 … 10000
   * @param {number[]} axis  [x, y, z], not all zero
   * @param {number} angle  degrees in [−360, 360]
   * @param {object} [options]  {centre?: [x, y, z], iterations?: 0 … 1000, source?}
   */
  constructor(targets, axis, angle, options = {}) {
    super('rotate_points', options);
    if (!Array.isArray(targets) || targets.length === 0) throw new TypeError('targets: select one point or more');
    if (targets.length > ROTATE_TARGETS_MAX) throw new TypeError(`targets: at most ${ROTATE_TARGETS_MAX} points`);
    this.targets = targets.map(compositeTarget);
    this.axis = vector3(axis, 'axis');
    if (this.axis.every((x) => x === 0)) throw new TypeError('axis: has no direction (all zero)');
    if (typeof angle !== 'number' || !Number.isFinite(angle) || Math.abs(angle) > ROTATE_ANGLE_MAX) {
      throw new TypeError(`angle: expected degrees in [−${ROTATE_ANGLE_MAX}, ${ROTATE_ANGLE_MAX}]`);
    }
    this.angle = angle;
    if (options.centre !== undefined && options.centre !== null) this.centre = vector3(options.centre, 'centre');
    const it = options.iterations;
    if (it !== undefined && it !== null) {
      if (!Number.isInteger(it) || it < 0 || it > ROTATE_ITERATIONS_MAX) throw new TypeError(`iterations: expected an integer in [0, ${ROTATE_ITERATIONS_MAX}]`);
      this.iterations = it;
    }
    const n = this.targets.length;
    this.name = `rotate ${n} point${n === 1 ? '' : 's'} by ${angle}°`;
  }

  fields() {
    return {
      targets: this.targets.map((t) => ({ ...t })),
      axis: this.axis.slice(),
      centre: this.centre ? this.centre.slice() : undefined,
      angle: this.angle,
      iterations: this.iterations,
    };
  }
}
