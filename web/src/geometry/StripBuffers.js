// Preallocated three.js buffers for a strip's geometry, updated in place from the protocol's
// `geometry` objects. A buffer is reallocated only when its size changes (then the geometry is
// disposed so the renderer frees the old GPU buffers); otherwise the data is decoded straight into
// the existing typed array and only the update range is flagged.

import { BufferAttribute, BufferGeometry, DynamicDrawUsage } from 'three';
import { decodeArrayInto, elementCount } from './decode.js';
import { fillColors, niceRange } from './colormap.js';

/**
 * Makes sure `geometry` has a float attribute `name` of exactly `length` elements.
 * Returns {attribute, reallocated}.
 */
export function ensureFloatAttribute(geometry, name, length, itemSize) {
  const existing = geometry.getAttribute(name);
  if (existing && existing.array.length === length && existing.itemSize === itemSize) {
    return { attribute: existing, reallocated: false };
  }
  if (existing) geometry.dispose();
  const attribute = new BufferAttribute(new Float32Array(length), itemSize);
  attribute.setUsage(DynamicDrawUsage);
  geometry.setAttribute(name, attribute);
  return { attribute, reallocated: true };
}

/** Flags a whole attribute for upload (update range = everything). */
export function markUpdated(attribute) {
  attribute.clearUpdateRanges();
  attribute.addUpdateRange(0, attribute.array.length);
  attribute.needsUpdate = true;
}

/**
 * Decodes an encoded float32 array into the attribute `name` of `geometry`, in place when the
 * size is unchanged. Returns {attribute, reallocated}.
 */
export function updateFloatAttribute(geometry, name, spec, itemSize) {
  const result = ensureFloatAttribute(geometry, name, elementCount(spec), itemSize);
  decodeArrayInto(spec, result.attribute.array);
  markUpdated(result.attribute);
  return result;
}

/** Returns `array` if it has `length` elements of `Type`, else a new one. */
function sized(array, Type, length) {
  return array instanceof Type && array.length === length ? array : new Type(length);
}

/** Triangle index (two per quad) from quads [F,4]. */
export function quadsToTriangles(quads, vertexCount) {
  const f = quads.length / 4;
  const Type = vertexCount > 65535 ? Uint32Array : Uint16Array;
  const index = new Type(f * 6);
  for (let q = 0; q < f; q++) {
    const a = quads[4 * q], b = quads[4 * q + 1], c = quads[4 * q + 2], d = quads[4 * q + 3];
    index.set([a, b, c, a, c, d], 6 * q);
  }
  return index;
}

/** Index for a closed polyline: 0, 1, …, n−1, 0. */
function loopIndex(n) {
  const index = new (n > 65535 ? Uint32Array : Uint16Array)(n + 1);
  for (let i = 0; i < n; i++) index[i] = i;
  index[n] = 0;
  return index;
}

export class StripBuffers {
  constructor() {
    this.kind = 'strip';
    this.surface = new BufferGeometry();
    this.curves = { a: new BufferGeometry(), b: new BufferGeometry() };
    this.polygons = { a: new BufferGeometry(), b: new BufferGeometry() };
    this.rulings = new BufferGeometry();
    this.normals = new BufferGeometry();
    /** Control points per curve: the polygon's position arrays themselves ([n·3]). */
    this.controlPoints = { a: new Float32Array(0), b: new Float32Array(0) };
    this.warp = new Float32Array(0);
    this.development = { vertices: new Float32Array(0), quads: new Int32Array(0), count: 0 };
    this.grid = [0, 0];
    this.closed = false;
    this.colorRange = niceRange(0);
    this.warpMax = 0;
    /** Increments on every apply; `structureVersion` only when some buffer was reallocated. */
    this.version = 0;
    this.structureVersion = 0;
    this.hasData = false;
    this._surfaceQuads = null;
    this._surfaceQuadsText = null;
    this._rulingsScratch = new Float32Array(0);
    this._normalsScratch = new Float32Array(0);
    this._closedIndex = { a: null, b: null };
  }

  /** Applies one protocol geometry object. Returns true if a buffer was reallocated. */
  apply(g) {
    if (!g || g.kind !== 'strip') throw new Error(`unsupported geometry kind ${g && g.kind}`);
    let realloc = false;
    this.closed = !!g.surface.closed;

    // Surface positions.
    const s = g.surface;
    realloc = updateFloatAttribute(this.surface, 'position', s.vertices, 3).reallocated || realloc;
    const vertexCount = s.vertices.shape[0];
    this.grid = s.grid ? s.grid.slice() : [vertexCount, 1];

    // Surface index: rebuilt only when the quads change.
    if (s.quads.data !== this._surfaceQuadsText || realloc) {
      this._surfaceQuads = sized(this._surfaceQuads, Int32Array, elementCount(s.quads));
      decodeArrayInto(s.quads, this._surfaceQuads);
      this.surface.setIndex(new BufferAttribute(quadsToTriangles(this._surfaceQuads, vertexCount), 1));
      this._surfaceQuadsText = s.quads.data;
      realloc = true;
    }

    // Warp angle → vertex colours.
    if (s.warp_angle_deg) {
      this.warp = sized(this.warp, Float32Array, elementCount(s.warp_angle_deg));
      decodeArrayInto(s.warp_angle_deg, this.warp);
    } else {
      this.warp = sized(this.warp, Float32Array, vertexCount);
      this.warp.fill(0);
    }
    let max = 0;
    for (let i = 0; i < this.warp.length; i++) if (this.warp[i] > max) max = this.warp[i];
    this.warpMax = max;
    this.colorRange = niceRange(max);
    const color = ensureFloatAttribute(this.surface, 'color', vertexCount * 3, 3);
    realloc = color.reallocated || realloc;
    fillColors(this.warp, color.attribute.array, this.colorRange);
    markUpdated(color.attribute);

    this.surface.computeVertexNormals();
    markUpdated(this.surface.getAttribute('normal'));
    this.surface.computeBoundingSphere();
    this.surface.computeBoundingBox();

    // Curves and control polygons.
    for (const c of ['a', 'b']) {
      if (g.curves && g.curves[c]) {
        const r = updateFloatAttribute(this.curves[c], 'position', g.curves[c], 3);
        realloc = r.reallocated || realloc;
        this._setLoop(this.curves[c], g.curves[c].shape[0], r.reallocated);
      }
      if (g.control_points && g.control_points[c]) {
        const r = updateFloatAttribute(this.polygons[c], 'position', g.control_points[c], 3);
        realloc = r.reallocated || realloc;
        this.controlPoints[c] = r.attribute.array;
        this._setLoop(this.polygons[c], g.control_points[c].shape[0], r.reallocated);
        this.polygons[c].computeBoundingSphere();
      }
    }

    // Rulings: [R,6] is exactly R line segments.
    if (g.rulings) {
      realloc = updateFloatAttribute(this.rulings, 'position', g.rulings, 3).reallocated || realloc;
    }

    // Normals: a segment from each ruling's midpoint along its normal.
    if (g.normals && g.rulings) {
      const R = g.normals.shape[0];
      this._normalsScratch = sized(this._normalsScratch, Float32Array, R * 3);
      decodeArrayInto(g.normals, this._normalsScratch);
      const rul = this.rulings.getAttribute('position').array;
      const segs = ensureFloatAttribute(this.normals, 'position', R * 6, 3);
      realloc = segs.reallocated || realloc;
      let meanLen = 0;
      for (let r = 0; r < R; r++) {
        const o = 6 * r;
        meanLen += Math.hypot(rul[o + 3] - rul[o], rul[o + 4] - rul[o + 1], rul[o + 5] - rul[o + 2]);
      }
      const len = R > 0 ? (0.35 * meanLen) / R : 0;
      const out = segs.attribute.array;
      const n = this._normalsScratch;
      for (let r = 0; r < R; r++) {
        const o = 6 * r;
        const mx = 0.5 * (rul[o] + rul[o + 3]);
        const my = 0.5 * (rul[o + 1] + rul[o + 4]);
        const mz = 0.5 * (rul[o + 2] + rul[o + 5]);
        const nl = Math.hypot(n[3 * r], n[3 * r + 1], n[3 * r + 2]) || 1;
        out[o] = mx;
        out[o + 1] = my;
        out[o + 2] = mz;
        out[o + 3] = mx + (len * n[3 * r]) / nl;
        out[o + 4] = my + (len * n[3 * r + 1]) / nl;
        out[o + 5] = mz + (len * n[3 * r + 2]) / nl;
      }
      markUpdated(segs.attribute);
    }

    // Development (2D): kept as plain arrays for the 2D view.
    if (g.development) {
      const d = g.development;
      const nv = elementCount(d.vertices);
      if (this.development.vertices.length !== nv) realloc = true;
      this.development.vertices = sized(this.development.vertices, Float32Array, nv);
      decodeArrayInto(d.vertices, this.development.vertices);
      this.development.count = d.vertices.shape[0];
      const nq = elementCount(d.quads);
      if (this.development.quads.length !== nq || d.quads.data !== this._devQuadsText) {
        this.development.quads = sized(this.development.quads, Int32Array, nq);
        decodeArrayInto(d.quads, this.development.quads);
        this._devQuadsText = d.quads.data;
      }
    } else {
      this.development.count = 0;
    }

    this.version++;
    if (realloc) this.structureVersion++;
    this.hasData = true;
    return realloc;
  }

  _setLoop(geometry, n, reallocated) {
    if (this.closed) {
      if (reallocated || !geometry.index || geometry.index.count !== n + 1) geometry.setIndex(new BufferAttribute(loopIndex(n), 1));
    } else if (geometry.index) {
      geometry.setIndex(null);
    }
  }

  /** Targets of every control point ({curve, index}, curve a first). */
  pointTargets() {
    const na = this.count('a'), nb = this.count('b');
    if (!this._targets || this._targets.length !== na + nb || this._targetsA !== na) {
      this._targets = [];
      for (const c of ['a', 'b']) for (let i = 0; i < this.count(c); i++) this._targets.push({ curve: c, index: i });
      this._targetsA = na;
    }
    return this._targets;
  }

  /** [x, y, z] of a target {curve, index}, or null. */
  pointOf(t) {
    return t && t.curve !== undefined ? this.point(t.curve, t.index) : null;
  }

  /** Number of control points of a curve. */
  count(curve) {
    return this.controlPoints[curve].length / 3;
  }

  /** [x, y, z] of a control point, or null. */
  point(curve, index) {
    const p = this.controlPoints[curve];
    if (!p || index < 0 || 3 * index + 2 >= p.length) return null;
    return [p[3 * index], p[3 * index + 1], p[3 * index + 2]];
  }

  dispose() {
    for (const g of [this.surface, this.curves.a, this.curves.b, this.polygons.a, this.polygons.b, this.rulings, this.normals]) g.dispose();
  }
}
