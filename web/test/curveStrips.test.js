// Buffers of the strips between two given curves (quasi_strip, conical_strip) and the σ plot's data.
import { describe, expect, it } from 'vitest';
import { encodeArray } from '../src/geometry/decode.js';
import { PATCH_TYPE_COLORS, StripBuffers } from '../src/geometry/StripBuffers.js';
import { mappingChange, mappingColumns } from '../src/ui/MappingPlot.js';

const f32 = (rows, cols, values) => encodeArray(new Float32Array(values), [rows, cols]);
const i32 = (rows, cols, values) => encodeArray(new Int32Array(values), [rows, cols]);

/** A quasi_strip geometry of 3 rulings (U = 3, V = 2). */
function quasiGeometry(warp = [0.5, 1.5, 3]) {
  return {
    kind: 'quasi_strip',
    surface: {
      vertices: f32(6, 3, [0, 0, 0, 0, 1, 0, 1, 0, 0, 1, 1, 0, 2, 0, 0, 2, 1, 0]),
      quads: i32(2, 4, [0, 2, 3, 1, 2, 4, 5, 3]),
      grid: [3, 2], closed: false,
      warp_angle_deg: f32(6, 1, [warp[0], warp[0], warp[1], warp[1], warp[2], warp[2]]),
    },
    rulings: f32(1, 6, [0, 0, 0, 0, 1, 0]),
    curves: { c1: f32(2, 3, [0, 0, 0, 2, 0, 0]), c2: f32(2, 3, [0, 1, 0, 2, 1, 0]) },
    control_points: { c1: f32(3, 3, [0, 0, 0, 1, 0, 0.5, 2, 0, 0]), c2: f32(2, 3, [0, 1, 0, 2, 1, 0]) },
    mapping: {
      sigma: f32(3, 2, [0, 0, 0.5, 0.3, 1, 1]),
      initial: f32(3, 2, [0, 0, 0.5, 0.5, 1, 1]),
      samples: f32(2, 2, [0, 0.5, 1, 3]),
      trim: [0, 1], domain_c1: [0, 1], domain_c2: [0, 1],
    },
    development: { vertices: f32(6, 2, [0, 0, 0, 1, 1, 0, 1, 1, 2, 0, 2, 1]), quads: i32(2, 4, [0, 2, 3, 1, 2, 4, 5, 3]) },
  };
}

/** A conical_strip geometry of 2 patches (a triangle, a quadrilateral), 2 rungs each. */
function conicalGeometry() {
  const v = [0, 0, 0, 0, 1, 0, 1, 0, 0, 1, 1, 0, 1, 0, 0, 1, 1, 0, 2, 0, 0, 2, 1, 0];
  return {
    kind: 'conical_strip',
    surface: {
      vertices: f32(8, 3, v),
      quads: i32(2, 4, [0, 2, 3, 1, 4, 6, 7, 5]),
      quad_patch: i32(2, 1, [0, 1]),
      patch_type: f32(8, 1, [3, 3, 3, 3, 4, 4, 4, 4]),
      normal_jump_deg: f32(8, 1, [0, 0, 2, 2, 2, 2, 0, 0]),
    },
    patches: { type: i32(2, 1, [3, 4]), base: 'PQ', normal_jump_deg: f32(2, 1, [2, 2]), projection_points: f32(2, 3, [0, 0, 5, 0, 0, 6]) },
    rulings: f32(3, 6, [0, 0, 0, 0, 1, 0, 1, 0, 0, 1, 1, 0, 2, 0, 0, 2, 1, 0]),
    curves: { p: f32(2, 3, [0, 0, 0, 2, 0, 0]), q: f32(2, 3, [0, 1, 0, 2, 1, 0]) },
    control_points: { p: f32(2, 3, [0, 0, 0, 2, 0, 0]), q: f32(3, 3, [0, 1, 0, 1, 1.2, 0, 2, 1, 0]) },
    samples: { p: f32(2, 3, [0, 0, 0, 2, 0, 0]), q: f32(2, 3, [0, 1, 0, 2, 1, 0]) },
    development: { vertices: f32(8, 2, v.filter((_, i) => i % 3 !== 2)), quads: i32(2, 4, [0, 2, 3, 1, 4, 6, 7, 5]), quad_patch: i32(2, 1, [0, 1]) },
  };
}

describe('quasi_strip buffers', () => {
  it('colour by warp angle, address control points as c1/c2 and keep σ before and after', () => {
    const b = new StripBuffers();
    b.apply(quasiGeometry());
    expect(b.modelKind).toBe('quasi_strip');
    expect(b.curveNames).toEqual(['c1', 'c2']);
    expect(b.warpMax).toBe(3);
    expect(b.colorInfo.title).toBe('warp angle');
    expect(b.pointTargets().map((t) => `${t.curve}${t.index}`)).toEqual(['c10', 'c11', 'c12', 'c20', 'c21']);
    expect(b.pointOf({ curve: 'c1', index: 1 })).toEqual([1, 0, 0.5]);
    expect(b.pointOf({ curve: 'a', index: 1 })).toEqual([1, 0, 0.5]);  // the slot itself
    expect(b.pointOf({ curve: 'p', index: 0 })).toBeNull();
    const columns = mappingColumns(b.mapping);
    expect(columns).toEqual([[0, 0.5, 1], [0, 0.5, 1], [0, expect.closeTo(0.3, 6), 1]]);
    expect(mappingChange(columns)).toBeCloseTo(0.2, 6);
  });
});

describe('conical_strip buffers', () => {
  it('colour by normal jump or by patch type and colour the unfolded patches likewise', () => {
    const b = new StripBuffers();
    b.apply(conicalGeometry());
    expect(b.curveNames).toEqual(['p', 'q']);
    expect(b.count('q')).toBe(3);
    expect(b.colorInfo.title).toBe('normal jump');
    expect(b.warpMax).toBe(2);
    expect(b.mapping).toBeNull();
    expect([...b.patches.type]).toEqual([3, 4]);
    expect([...b.development.quadPatch]).toEqual([0, 1]);
    expect([...b.development.quadValue]).toEqual([2, 2]);
    b.setColorMode('patch_type');
    expect(b.categorical).toBe(true);
    expect([...b.development.quadValue]).toEqual([3, 4]);
    const colors = b.surface.getAttribute('color').array;
    expect(colors[0]).toBeCloseTo(PATCH_TYPE_COLORS[3][0], 6);
    expect(colors[3 * 7 + 2]).toBeCloseTo(PATCH_TYPE_COLORS[4][2], 6);
    expect(() => b.setColorMode('rainbow')).toThrow(TypeError);
  });

  it('an unsolved geometry (no surface) is refused with a message', () => {
    const b = new StripBuffers();
    expect(() => b.apply({ kind: 'conical_strip', surface: null })).toThrow(/not solved/);
  });
});
