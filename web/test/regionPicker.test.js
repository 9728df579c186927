// The region tools' geometry (issue 15): the lasso's point-in-loop test and the coarse z-buffer
// that keeps a lasso to the side of a shape facing the viewer. Checked against independent
// computations: a circle's area by counting lattice points, and a sphere's near hemisphere.
import { describe, expect, it } from 'vitest';
import { insidePolygon, visiblePoints } from '../src/ui/RegionPicker.js';

describe('insidePolygon', () => {
  it('counts the lattice points of a 64-gon like a circle of the same area', () => {
    const r = 40, loop = [];
    for (let k = 0; k < 64; ++k) loop.push([r * Math.cos((2 * Math.PI * k) / 64), r * Math.sin((2 * Math.PI * k) / 64)]);
    let inside = 0;
    for (let x = -50; x <= 50; ++x) for (let y = -50; y <= 50; ++y) if (insidePolygon(loop, x + 0.5, y + 0.5)) ++inside;
    const area = 0.5 * 64 * r * r * Math.sin((2 * Math.PI) / 64);  // the 64-gon's own area
    expect(Math.abs(inside - area) / area).toBeLessThan(0.01);
  });

  it('holds for concave loops, whichever way round they are drawn', () => {
    const c = [[0, 0], [10, 0], [10, 10], [5, 3], [0, 10]];  // a notch from the top
    for (const loop of [c, [...c].reverse()]) {
      expect(insidePolygon(loop, 2, 2)).toBe(true);
      expect(insidePolygon(loop, 5, 8)).toBe(false);  // in the notch
      expect(insidePolygon(loop, 11, 5)).toBe(false);
      expect(insidePolygon(loop, 9, 8)).toBe(true);
    }
  });
});

describe('visiblePoints', () => {
  it('keeps the near hemisphere of a densely sampled sphere and drops the far one', () => {
    // A unit sphere 5 units in front of an orthographic camera looking down −z: x, y are the
    // normalized device coordinates (sphere radius 0.5 of the view), depth = 5 − z.
    const n = 20000, ndc = new Float32Array(3 * n), z = [];
    let seed = 7;
    const random = () => ((seed = (seed * 16807) % 2147483647) / 2147483647);
    for (let i = 0; i < n; ++i) {
      const u = 2 * random() - 1, t = 2 * Math.PI * random(), s = Math.sqrt(1 - u * u);
      const p = [s * Math.cos(t), s * Math.sin(t), u];
      ndc[3 * i] = 0.5 * p[0];
      ndc[3 * i + 1] = 0.5 * p[1];
      ndc[3 * i + 2] = 5 - p[2];
      z.push(p[2]);
    }
    // The picker's rule: tolerance 1 % of the bounding box's diagonal (2√3) plus a cell's width
    // (6 px: 0.06 of the radius), separation three tolerances.
    const tolerance = 0.01 * 2 * Math.sqrt(3) + 0.06;
    const visible = visiblePoints(ndc, 400, 400, tolerance, 3 * tolerance);
    let farSeen = 0, near = 0, nearSeen = 0;
    for (let i = 0; i < n; ++i) {
      // Away from the silhouette (|z| > 0.3) the answer is clear-cut: seen iff on the near side.
      if (Math.abs(z[i]) < 0.3) continue;
      if (z[i] > 0) {
        ++near;
        nearSeen += visible[i];
      } else farSeen += visible[i];
    }
    expect(near).toBeGreaterThan(6000);
    expect(farSeen).toBe(0);
    // Near the rim the surface turns away steeply and some of its points count as hidden.
    expect(nearSeen / near).toBeGreaterThan(0.9);  // measured 0.958
  });

  it('drops points behind the camera or outside the view', () => {
    const ndc = new Float32Array([0, 0, -1, 1.5, 0, 2, 0, 0, 2]);
    expect(Array.from(visiblePoints(ndc, 100, 100, 0.1))).toEqual([0, 0, 1]);
  });
});
