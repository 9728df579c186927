import { describe, expect, it } from 'vitest';
import { BufferGeometry } from 'three';
import { base64ByteLength, decodeArray, decodeArrayInto, decodeBase64, encodeArray, encodeBase64 } from '../src/geometry/decode.js';
import { StripBuffers, updateFloatAttribute } from '../src/geometry/StripBuffers.js';
import { colorAt, niceRange } from '../src/geometry/colormap.js';

const b64 = (bytes) => Buffer.from(bytes).toString('base64');

describe('base64 decoding', () => {
  it('decodes every padding case like Node does', () => {
    for (let n = 0; n < 20; n++) {
      const bytes = Uint8Array.from({ length: n }, (_, i) => (i * 37 + 11) & 255);
      const text = b64(bytes);
      expect(base64ByteLength(text)).toBe(n);
      expect([...decodeBase64(text)]).toEqual([...bytes]);
      expect(encodeBase64(bytes)).toBe(text);
    }
  });

  it('rejects invalid characters', () => {
    expect(() => decodeBase64('AA*A')).toThrow();
  });

  it('decodes float32 and int32 arrays (little-endian, row-major)', () => {
    const f = new Float32Array([0, 1.5, -2.25, 3e-7, 1e10, -0]);
    const spec = { dtype: 'float32', shape: [2, 3], data: Buffer.from(f.buffer).toString('base64') };
    const out = decodeArray(spec);
    expect(out.shape).toEqual([2, 3]);
    expect(out.data).toBeInstanceOf(Float32Array);
    expect([...out.data]).toEqual([...f]);
    const i = new Int32Array([0, 1, -1, 2147483647, -2147483648, 96]);
    const ispec = { dtype: 'int32', shape: [3, 2], data: Buffer.from(i.buffer).toString('base64') };
    expect([...decodeArray(ispec).data]).toEqual([...i]);
  });

  it('decodes into an existing array and checks the size', () => {
    const target = new Float32Array(3);
    const spec = encodeArray(new Float32Array([1, 2, 3]), [1, 3]);
    expect(decodeArrayInto(spec, target)).toBe(target);
    expect([...target]).toEqual([1, 2, 3]);
    expect(() => decodeArrayInto(spec, new Float32Array(4))).toThrow();
    expect(() => decodeArrayInto(spec, new Int32Array(3))).toThrow();
    expect(() => decodeArrayInto({ ...spec, shape: [2, 3] }, new Float32Array(6))).toThrow();
  });
});

describe('in-place attribute updates', () => {
  it('keeps the same array for the same size and flags the update range', () => {
    const g = new BufferGeometry();
    const first = updateFloatAttribute(g, 'position', encodeArray(new Float32Array([1, 2, 3, 4, 5, 6]), [2, 3]), 3);
    expect(first.reallocated).toBe(true);
    const array = first.attribute.array;
    const version = first.attribute.version;
    const second = updateFloatAttribute(g, 'position', encodeArray(new Float32Array([6, 5, 4, 3, 2, 1]), [2, 3]), 3);
    expect(second.reallocated).toBe(false);
    expect(second.attribute).toBe(first.attribute);
    expect(second.attribute.array).toBe(array);
    expect([...array]).toEqual([6, 5, 4, 3, 2, 1]);
    expect(second.attribute.version).toBeGreaterThan(version);
    expect(second.attribute.updateRanges).toEqual([{ start: 0, count: 6 }]);
  });

  it('reallocates when the size changes', () => {
    const g = new BufferGeometry();
    const a = updateFloatAttribute(g, 'position', encodeArray(new Float32Array(6), [2, 3]), 3).attribute.array;
    const r = updateFloatAttribute(g, 'position', encodeArray(new Float32Array([1, 2, 3, 4, 5, 6, 7, 8, 9]), [3, 3]), 3);
    expect(r.reallocated).toBe(true);
    expect(r.attribute.array).not.toBe(a);
    expect(r.attribute.array.length).toBe(9);
    expect(g.getAttribute('position')).toBe(r.attribute);
  });
});

// A small strip geometry message: U samples × 2, n control points per curve, R rulings.
function stripGeometry(U, n, R, lift = 0) {
  const V = 2;
  const vertices = new Float32Array(U * V * 3);
  const warp = new Float32Array(U * V);
  const dev = new Float32Array(U * V * 2);
  for (let i = 0; i < U; i++) {
    for (let j = 0; j < V; j++) {
      const k = i * V + j;
      vertices.set([i, j, lift * i * j], 3 * k);
      warp[k] = i;
      dev.set([i, j], 2 * k);
    }
  }
  const quads = new Int32Array((U - 1) * 4);
  for (let i = 0; i + 1 < U; i++) quads.set([i * V, (i + 1) * V, (i + 1) * V + 1, i * V + 1], 4 * i);
  const curve = (j) => {
    const c = new Float32Array(U * 3);
    for (let i = 0; i < U; i++) c.set([i, j, 0], 3 * i);
    return encodeArray(c, [U, 3]);
  };
  const cp = (j) => {
    const c = new Float32Array(n * 3);
    for (let i = 0; i < n; i++) c.set([i, j, lift], 3 * i);
    return encodeArray(c, [n, 3]);
  };
  const rulings = new Float32Array(R * 6);
  const normals = new Float32Array(R * 3);
  for (let r = 0; r < R; r++) {
    rulings.set([r, 0, 0, r, 1, 0], 6 * r);
    normals.set([0, 0, 2], 3 * r);
  }
  return {
    kind: 'strip',
    surface: { vertices: encodeArray(vertices, [U * V, 3]), quads: encodeArray(quads, [U - 1, 4]), grid: [U, V], closed: false, warp_angle_deg: encodeArray(warp, [U * V, 1]) },
    curves: { a: curve(0), b: curve(1) },
    control_points: { a: cp(0), b: cp(1) },
    rulings: encodeArray(rulings, [R, 6]),
    normals: encodeArray(normals, [R, 3]),
    development: { vertices: encodeArray(dev, [U * V, 2]), quads: encodeArray(quads, [U - 1, 4]) },
  };
}

describe('StripBuffers', () => {
  it('updates every buffer in place across iterates of the same size', () => {
    const s = new StripBuffers();
    expect(s.apply(stripGeometry(8, 5, 4))).toBe(true);
    const arrays = {
      pos: s.surface.getAttribute('position').array,
      color: s.surface.getAttribute('color').array,
      normal: s.surface.getAttribute('normal').array,
      index: s.surface.index,
      a: s.controlPoints.a,
      rulings: s.rulings.getAttribute('position').array,
      normals: s.normals.getAttribute('position').array,
      dev: s.development.vertices,
    };
    const structure = s.structureVersion;
    expect(s.apply(stripGeometry(8, 5, 4, 0.5))).toBe(false);
    expect(s.structureVersion).toBe(structure);
    expect(s.surface.getAttribute('position').array).toBe(arrays.pos);
    expect(s.surface.getAttribute('color').array).toBe(arrays.color);
    expect(s.surface.getAttribute('normal').array).toBe(arrays.normal);
    expect(s.surface.index).toBe(arrays.index);
    expect(s.controlPoints.a).toBe(arrays.a);
    expect(s.controlPoints.a).toBe(s.polygons.a.getAttribute('position').array);
    expect(s.rulings.getAttribute('position').array).toBe(arrays.rulings);
    expect(s.normals.getAttribute('position').array).toBe(arrays.normals);
    expect(s.development.vertices).toBe(arrays.dev);
    expect(s.point('a', 2)).toEqual([2, 0, 0.5]);
    expect(s.count('b')).toBe(5);
    // Triangulated quads: 7 quads → 14 triangles.
    expect(s.surface.index.count).toBe(7 * 6);
    // Warp colours use a nice range ≥ the maximum (7°).
    expect(s.warpMax).toBe(7);
    expect(s.colorRange).toBe(10);
    // Normals: segments start at the ruling midpoints.
    expect([...arrays.normals.slice(0, 3)]).toEqual([0, 0.5, 0]);
  });

  it('reallocates when the sizes change', () => {
    const s = new StripBuffers();
    s.apply(stripGeometry(8, 5, 4));
    const pos = s.surface.getAttribute('position').array;
    const a = s.controlPoints.a;
    const structure = s.structureVersion;
    expect(s.apply(stripGeometry(12, 9, 6))).toBe(true);
    expect(s.structureVersion).toBe(structure + 1);
    expect(s.surface.getAttribute('position').array).not.toBe(pos);
    expect(s.surface.getAttribute('position').array.length).toBe(12 * 2 * 3);
    expect(s.controlPoints.a).not.toBe(a);
    expect(s.count('a')).toBe(9);
    expect(s.development.count).toBe(24);
  });
});

describe('colour map', () => {
  it('uses nice ranges of at least 1°', () => {
    expect(niceRange(0)).toBe(1);
    expect(niceRange(1e-9)).toBe(1);
    expect(niceRange(1.2)).toBe(2);
    expect(niceRange(9.86)).toBe(10);
    expect(niceRange(54)).toBe(100);
    expect(niceRange(24)).toBe(25);
  });
  it('clamps and interpolates', () => {
    const lo = colorAt(-1, [0, 0, 0]);
    const hi = colorAt(2, [0, 0, 0]);
    expect(lo).toEqual(colorAt(0, [0, 0, 0]));
    expect(hi).toEqual(colorAt(1, [0, 0, 0]));
    expect(hi[0]).toBeGreaterThan(lo[0]);
  });
});
