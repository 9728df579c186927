import { Command } from './Command.js';

// Drawing the crease pattern (composite sessions made from a drawing, issue 16 item 3): strokes on
// the flat sheet (scene model.drawing.strokes; stroke index = crease index). Every edit is
// structural: the server rebuilds the flat composite from the drawing (fold amount back to 0),
// journals it, and sends the scene to everyone as an `update`.

/** Assignments a drawn crease can carry: mountain, valley, flat (drawn, not folded), cut. */
export const DRAW_ASSIGNMENTS = ['M', 'V', 'F', 'C'];
/** Points a stroke may have. */
export const STROKE_POINTS_MIN = 2;
export const STROKE_POINTS_MAX = 200;
/** Largest crease index a message may name (as the schema's edge indices). */
const CREASE_MAX = 99999;

/** Points on the sheet: 2..200 pairs of finite numbers, copied as plain arrays. */
export function sheetPoints(points, field = 'points') {
  if (!points || typeof points.length !== 'number') throw new TypeError(`${field}: expected an array of [x, y] points`);
  if (points.length < STROKE_POINTS_MIN || points.length > STROKE_POINTS_MAX) {
    throw new TypeError(`${field}: expected ${STROKE_POINTS_MIN} to ${STROKE_POINTS_MAX} points, got ${points.length}`);
  }
  return Array.from(points, (p, i) => {
    if (!p || p.length !== 2) throw new TypeError(`${field}[${i}]: expected [x, y]`);
    const q = [Number(p[0]), Number(p[1])];
    if (!q.every(Number.isFinite)) throw new TypeError(`${field}[${i}]: expected 2 finite numbers`);
    return q;
  });
}

/** curved: false needs exactly 2 points (a straight crease), true at least 3 (a spline through them). */
export function checkCurved(curved, count, field = 'curved') {
  if (typeof curved !== 'boolean') throw new TypeError(`${field}: expected true or false`);
  if (!curved && count !== 2) throw new TypeError(`points: a straight crease has exactly 2 points, got ${count}`);
  if (curved && count < 3) throw new TypeError(`points: a curved crease has at least 3 points, got ${count}`);
  return curved;
}

export function checkAssignment(assignment) {
  if (!DRAW_ASSIGNMENTS.includes(assignment)) throw new TypeError(`assignment: expected one of ${DRAW_ASSIGNMENTS.join(', ')}`);
  return assignment;
}

/** A fold angle magnitude in degrees, 0 < a ≤ 180 (the sign comes from M/V); undefined stays. */
export function checkFoldAngle(angle) {
  if (angle === undefined || angle === null) return undefined;
  if (typeof angle !== 'number' || !Number.isFinite(angle) || angle <= 0 || angle > 180) {
    throw new TypeError('fold_angle: expected degrees, 0 < angle ≤ 180');
  }
  return angle;
}

export function checkCrease(crease) {
  if (!Number.isInteger(crease) || crease < 0 || crease > CREASE_MAX) throw new TypeError('crease: expected an integer ≥ 0');
  return crease;
}

export const ASSIGNMENT_NAMES = { M: 'mountain', V: 'valley', F: 'flat', C: 'cut', B: 'outline' };

/**
 * Draws a crease: a straight one through 2 points or a curved one (a spline) through ≥ 3, both
 * ends on the outline or on another crease; `foldAngle` is the magnitude in degrees (M and V only).
 */
export class DrawCreaseCommand extends Command {
  constructor(points, { curved = false, assignment = 'V', foldAngle } = {}, options) {
    super('draw_crease', options);
    this.points = sheetPoints(points);
    this.curved = checkCurved(curved, this.points.length);
    this.assignment = checkAssignment(assignment);
    this.foldAngle = assignment === 'M' || assignment === 'V' ? checkFoldAngle(foldAngle) : undefined;
    this.name = `draw a ${curved ? 'curved' : 'straight'} ${ASSIGNMENT_NAMES[this.assignment]} crease`;
  }

  fields() {
    return { points: this.points, curved: this.curved, assignment: this.assignment, fold_angle: this.foldAngle };
  }
}
