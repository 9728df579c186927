import { describe, expect, it } from 'vitest';
import { constrainedDragPosition, defaultGridStep, DRAG_CONSTRAINTS } from '../src/view/dragConstraint.js';
import { drawingDiagonal } from '../src/geometry/creaseDrawing.js';

const norm = (v) => { const l = Math.hypot(...v); return v.map((x) => x / l); };

describe('constrainedDragPosition', () => {
  const start = [1, 2, 3];
  // A pointer ray from a camera at (10, 0, 1) looking towards −x, slightly up.
  const ray = { origin: [10, 0, 1], direction: norm([-1, 0.4, 0.3]) };
  const free = [1.5, 2.5, 3.5];

  it('free drags keep the view-plane position', () => {
    expect(constrainedDragPosition(start, free, ray)).toEqual(free);
  });

  it('an axis constraint moves along the axis only, to the point nearest the ray', () => {
    for (const axis of ['x', 'y', 'z']) {
      const p = constrainedDragPosition(start, free, ray, { constraint: axis });
      const k = 'xyz'.indexOf(axis);
      for (let j = 0; j < 3; j++) if (j !== k) expect(p[j]).toBeCloseTo(start[j], 12);
    }
    // y: the point of the line (1, t, 3) nearest the ray, found by brute force.
    const p = constrainedDragPosition(start, free, ray, { constraint: 'y' });
    let best = Infinity; let bestT = 0;
    for (let t = -20; t <= 20; t += 1e-3) {
      const q = [1, t, 3];
      const w = [q[0] - ray.origin[0], q[1] - ray.origin[1], q[2] - ray.origin[2]];
      const along = w[0] * ray.direction[0] + w[1] * ray.direction[1] + w[2] * ray.direction[2];
      const d = Math.hypot(w[0] - along * ray.direction[0], w[1] - along * ray.direction[1], w[2] - along * ray.direction[2]);
      if (d < best) { best = d; bestT = t; }
    }
    expect(p[1]).toBeCloseTo(bestT, 2);
  });

  it('a plane constraint is where the ray meets the plane through the start', () => {
    const p = constrainedDragPosition(start, free, ray, { constraint: 'xy' });
    expect(p[2]).toBeCloseTo(3, 12);
    // On the ray: (p − origin) ∥ direction.
    const w = [p[0] - ray.origin[0], p[1] - ray.origin[1], p[2] - ray.origin[2]];
    const s = Math.hypot(...w);
    for (let k = 0; k < 3; k++) expect(w[k] / s).toBeCloseTo(ray.direction[k], 9);
  });

  it('a plane seen edge-on takes the free position projected onto it', () => {
    const edgeOn = { origin: [10, 0, 3], direction: [-1, 0, 0] };
    const p = constrainedDragPosition(start, free, edgeOn, { constraint: 'xy' });
    expect(p).toEqual([1.5, 2.5, 3]);
  });

  it('snapping rounds the free coordinates to the grid, and only those', () => {
    expect(constrainedDragPosition(start, [1.26, 2.74, 3.01], ray, { snap: true, step: 0.5 })).toEqual([1.5, 2.5, 3]);
    const p = constrainedDragPosition([1.26, 2.74, 3.01], [1.26, 2.74, 3.01], ray, { constraint: 'xy', snap: true, step: 0.5 });
    expect(p[2]).toBeCloseTo(3.01, 12);  // the plane's own coordinate is not snapped
    expect(p[0] % 0.5).toBeCloseTo(0, 12);
    expect(p[1] % 0.5).toBeCloseTo(0, 12);
  });

  it('every listed constraint is handled', () => {
    for (const c of DRAG_CONSTRAINTS) {
      const p = constrainedDragPosition(start, free, ray, { constraint: c, snap: true, step: 0.25 });
      expect(p.every(Number.isFinite)).toBe(true);
    }
  });
});

describe('defaultGridStep', () => {
  it('is 1, 2 or 5 times a power of ten nearest a fiftieth of the size', () => {
    expect(defaultGridStep(200)).toBe(5);
    expect(defaultGridStep(250)).toBe(5);
    expect(defaultGridStep(3)).toBe(0.05);
    expect(defaultGridStep(1)).toBe(0.02);
    expect(defaultGridStep(Math.hypot(3000, 1000))).toBe(50);
    expect(defaultGridStep(Math.hypot(300, 100))).toBe(5);
    expect(defaultGridStep(0.04)).toBe(0.001);
    expect(defaultGridStep(0)).toBe(1);
  });

  it('keeps its step when the size changes a little (a sheet folding): no jump from 5 to 10', () => {
    expect(defaultGridStep(251)).toBe(5);
    expect(defaultGridStep(240)).toBe(5);
    for (let size = 1; size < 1e4; size *= 1.07) {
      const step = defaultGridStep(size);
      expect(step / (size / 50)).toBeGreaterThan(0.6);
      expect(step / (size / 50)).toBeLessThan(1.6);
    }
  });
});

describe('drawingDiagonal', () => {
  const sheet = (w, ht, creases = []) => ({ model: { kind: 'composite', drawing: { strokes: [
    { assignment: 'B', points: [[0, 0], [w, 0], [w, ht], [0, ht]], closed: true }, ...creases] } } });

  it('is the diagonal of the drawn sheet, whatever the surface does', () => {
    expect(drawingDiagonal(sheet(200, 150))).toBe(250);
    expect(drawingDiagonal(sheet(200, 150, [{ assignment: 'V', points: [[0, 75], [100, 90], [200, 75]], curved: true }]))).toBe(250);
    expect(defaultGridStep(drawingDiagonal(sheet(3000, 1000)))).toBe(50);
    expect(defaultGridStep(drawingDiagonal(sheet(200, 150)))).toBe(5);
  });

  it('is null for a scene without a drawing (the surface then gives the size)', () => {
    expect(drawingDiagonal(null)).toBeNull();
    expect(drawingDiagonal({ model: { kind: 'strip' } })).toBeNull();
    expect(drawingDiagonal({ model: { kind: 'composite', drawing: { strokes: [] } } })).toBeNull();
  });
});
