import { describe, expect, it } from 'vitest';
import {
  CURVE_POLYLINE_POINTS, catmullRom, drawingStrokes, fitTransform, foldAngleMagnitude, gridStep, hitPoint, hitStroke,
  insertionIndex, insideSheet, nearestOnPolyline, nearestOnSegment, outlineLoops, reshapedCurved, roundPoint, sheetBounds, snapPoint,
  strokeGeometry, strokePolyline, toScreen, toSheet,
} from '../src/geometry/creaseDrawing.js';

// A 200 × 150 sheet (one closed outline stroke), a vertical valley and a curved mountain.
const outline = { points: [[0, 0], [200, 0], [200, 150], [0, 150]], closed: true, assignment: 'B' };
const vertical = { points: [[100, 0], [100, 150]], assignment: 'V' };
const arc = { points: [[0, 75], [50, 90], [100, 97], [150, 90], [200, 75]], curved: true, assignment: 'M', fold_angle: -60 };
const strokes = [outline, vertical, arc];
const geometry = strokeGeometry(strokes);

describe('stroke polylines', () => {
  it('a curved stroke passes through its points (Catmull-Rom), its ends are its ends', () => {
    const line = strokePolyline(arc);
    expect(line.points.length).toBe(4 * 12 + 1);
    expect(line.span.length).toBe(line.points.length - 1);
    for (const [k, p] of arc.points.entries()) expect(line.points[k * 12]).toEqual(p);
    // Smooth between them: the samples bulge above the chords, below the top.
    const mid = line.points[18];
    expect(mid[1]).toBeGreaterThan(93.5);
    expect(mid[1]).toBeLessThan(97.5);
    expect(line.span[0]).toBe(0);
    expect(line.span[line.span.length - 1]).toBe(3);
  });

  it('straight, polyline, closed and many-point strokes', () => {
    expect(strokePolyline(vertical)).toEqual({ points: [[100, 0], [100, 150]], span: [0] });
    const closed = strokePolyline(outline);
    expect(closed.points.length).toBe(5);
    expect(closed.points[4]).toEqual([0, 0]);
    expect(closed.span).toEqual([0, 1, 2, 3]);
    const many = { curved: true, points: Array.from({ length: CURVE_POLYLINE_POINTS }, (_, i) => [i, Math.sin(i)]) };
    expect(strokePolyline(many).points.length).toBe(CURVE_POLYLINE_POINTS);
    const ring = catmullRom([[1, 0], [0, 1], [-1, 0], [0, -1]], true, 8);
    expect(ring.points.length).toBe(33);
    expect(ring.points[32]).toEqual([1, 0]);
    for (const p of ring.points) expect(Math.hypot(p[0], p[1])).toBeGreaterThan(0.85);
  });

  it('fold angle magnitudes: |fold_angle|, 180 (a full fold) when absent, none for F, C, B', () => {
    expect(foldAngleMagnitude(arc)).toBe(60);
    expect(foldAngleMagnitude(vertical)).toBe(180);
    expect(foldAngleMagnitude({ assignment: 'V', fold_angle: 135 })).toBe(135);
    expect(foldAngleMagnitude({ assignment: 'F' })).toBeUndefined();
    expect(foldAngleMagnitude(outline)).toBeUndefined();
    // A curved crease cannot fold flat: at 180° or without an angle it aims at 90°, as the server.
    expect(foldAngleMagnitude({ assignment: 'M', curved: true })).toBe(90);
    expect(foldAngleMagnitude({ assignment: 'V', curved: true, fold_angle: 180 })).toBe(90);
    expect(foldAngleMagnitude({ assignment: 'V', curved: true, fold_angle: 120 })).toBe(120);
  });

  it('reads the drawing of a scene', () => {
    expect(drawingStrokes({ model: { kind: 'composite', drawing: { strokes } } })).toBe(strokes);
    expect(drawingStrokes({ model: { kind: 'composite' } })).toBeNull();
    expect(drawingStrokes(null)).toBeNull();
  });
});

describe('fitting the sheet to the board', () => {
  it('fits, centres and flips y; toSheet inverts toScreen', () => {
    const b = sheetBounds(geometry);
    expect(b).toEqual({ x0: 0, y0: 0, x1: 200, y1: 150 });
    const t = fitTransform(b, 1000, 600, 20);
    expect(t.scale).toBeCloseTo(560 / 150);
    expect(toScreen(t, [100, 75])).toEqual([500, 300]);
    const top = toScreen(t, [0, 150]);
    expect(top[1]).toBeCloseTo(20);
    expect(top[0]).toBeCloseTo(500 - 100 * t.scale);
    const back = toSheet(t, toScreen(t, [37.5, 12.25]));
    expect(back[0]).toBeCloseTo(37.5, 10);
    expect(back[1]).toBeCloseTo(12.25, 10);
  });

  it('clicked points are rounded to a power of ten within the resolution', () => {
    expect(roundPoint([50.000002879016805, 86.00000057580336], 0.0286)).toEqual([50, 86]);
    expect(roundPoint([12.3456, -7.891], 0.05)).toEqual([12.35, -7.89]);
    expect(roundPoint([0.1 + 0.2, 1], 0.001)).toEqual([0.3, 1]);
    expect(roundPoint([1.234, 5], 0)).toEqual([1.234, 5]);
  });

  it('grid steps of 1, 2, 5 × 10^k at least the given px apart', () => {
    expect(gridStep(3.7)).toBe(5);
    expect(gridStep(0.5)).toBe(50);
    expect(gridStep(100)).toBe(0.2);
  });
});

describe('snapping', () => {
  it('nearest points on segments and polylines', () => {
    expect(nearestOnSegment([5, 3], [0, 0], [10, 0])).toEqual({ point: [5, 0], t: 0.5, distance: 3 });
    expect(nearestOnSegment([-5, 0], [0, 0], [10, 0]).point).toEqual([0, 0]);
    expect(nearestOnPolyline([11, 5], [[0, 0], [10, 0], [10, 10]])).toEqual({ point: [10, 5], segment: 1, distance: 1 });
  });

  it('to a stroke vertex first, then onto the nearest stroke, within the tolerance', () => {
    // Near a corner (a vertex) and near the outline: the corner wins.
    expect(snapPoint([1.5, 2], geometry, 3)).toMatchObject({ point: [0, 0], kind: 'vertex', stroke: 0 });
    // Near the left edge only: onto it.
    const edge = snapPoint([1.2, 40], geometry, 3);
    expect(edge).toMatchObject({ kind: 'stroke', stroke: 0 });
    expect(edge.point[0]).toBe(0);
    expect(edge.point[1]).toBeCloseTo(40, 10);
    // Near the vertical crease's end on the outline: the vertex of the nearer stroke point.
    expect(snapPoint([101, 1], geometry, 3).point).toEqual([100, 0]);
    // Near the middle of the vertical crease.
    const crease = snapPoint([98, 40], geometry, 3);
    expect(crease).toMatchObject({ kind: 'stroke', stroke: 1 });
    expect(crease.point[0]).toBe(100);
    expect(crease.point[1]).toBeCloseTo(40, 10);
    // Near the arc's point [50, 90].
    expect(snapPoint([51, 88], geometry, 3)).toMatchObject({ point: [50, 90], kind: 'vertex', stroke: 2 });
    // Nothing near: the point itself.
    expect(snapPoint([60, 40], geometry, 3)).toEqual({ point: [60, 40], kind: null, stroke: -1, distance: 0 });
    // A stroke left out (its own point moved): the next best.
    expect(snapPoint([98, 40], geometry, 3, { exclude: 1 }).kind).toBeNull();
  });

  it('onto a curved stroke: onto its spline, not its chords', () => {
    const s = snapPoint([75, 96.5], geometry, 3);
    expect(s.kind).toBe('stroke');
    expect(s.stroke).toBe(2);
    const line = strokePolyline(arc).points;
    expect(nearestOnPolyline(s.point, line).distance).toBeLessThan(1e-9);
    expect(s.point[1]).toBeGreaterThan(94);  // the chord from [50, 90] to [100, 97] is at 93.5
  });
});

describe('the sheet', () => {
  it('outline loops: a closed stroke, or open outline strokes chained end to end', () => {
    expect(outlineLoops(geometry).length).toBe(1);
    const pieces = strokeGeometry([
      { points: [[0, 0], [200, 0]], assignment: 'B' },
      { points: [[0, 150], [200, 150]], assignment: 'B' },
      { points: [[200, 150], [200, 0]], assignment: 'B' },
      { points: [[0, 150], [0, 0]], assignment: 'B' },
      vertical,
    ]);
    const loops = outlineLoops(pieces, 1e-6);
    expect(loops.length).toBe(1);
    expect(loops[0].length).toBe(5);
    expect(insideSheet([10, 10], loops)).toBe(true);
    expect(insideSheet([210, 10], loops)).toBe(false);
  });

  it('points on the sheet, on its outline within the tolerance, and off it', () => {
    const loops = outlineLoops(geometry);
    expect(insideSheet([50, 50], loops)).toBe(true);
    expect(insideSheet([-5, 50], loops)).toBe(false);
    expect(insideSheet([100, 151], loops)).toBe(false);
    expect(insideSheet([0, 50], loops, 0.01)).toBe(true);
    expect(insideSheet([-0.005, 50], loops, 0.01)).toBe(true);
    // A sheet with a hole (two loops, even-odd).
    const holed = [...loops, [[80, 60], [120, 60], [120, 90], [80, 90]]];
    expect(insideSheet([100, 75], holed)).toBe(false);
    expect(insideSheet([20, 75], holed)).toBe(true);
    expect(insideSheet([5, 5], [])).toBe(true);
  });
});

describe('picking and editing strokes', () => {
  it('picks the nearest crease before the outline', () => {
    expect(hitStroke([101, 0.5], geometry, 3)).toBe(1);
    expect(hitStroke([30, 1], geometry, 3)).toBe(0);
    expect(hitStroke([75, 95.5], geometry, 3)).toBe(2);
    expect(hitStroke([100, 97.5], geometry, 3)).toBe(1);  // on the vertical crease too: the nearer
    expect(hitStroke([60, 40], geometry, 3)).toBe(-1);
    expect(hitPoint([49, 91], arc.points, 3)).toBe(1);
    expect(hitPoint([75, 40], arc.points, 3)).toBe(-1);
  });

  it('a point goes in between the points of the span it is on', () => {
    expect(insertionIndex(geometry[2], [25, 84])).toBe(1);
    expect(insertionIndex(geometry[2], [125, 95])).toBe(3);
    expect(insertionIndex(geometry[1], [100, 30])).toBe(1);
    expect(insertionIndex(geometry[0], [0, 70])).toBe(4);  // the closing span of a closed stroke
  });

  it('reshaped strokes: 2 points straight, a straight crease with a third point curved, curves stay curved', () => {
    expect(reshapedCurved(vertical, 3)).toBe(true);
    expect(reshapedCurved(vertical, 2)).toBe(false);
    expect(reshapedCurved(arc, 4)).toBe(true);
    expect(reshapedCurved(arc, 2)).toBe(false);
    expect(reshapedCurved({ points: [[0, 0], [1, 0], [2, 1]], assignment: 'M' }, 4)).toBeUndefined();
  });
});
