// Buffers of a developable spline surface (issue 14; Jiang et al. 2020, Algorithm 2): the
// `spline` object of a quad_mesh geometry (proto Geometry.h, splineGeometryJson) — the control
// mesh M (points and edges), the limit surface M^∞ sampled on one grid per bicubic patch (6
// samples per knot span) with the scale-free Gauss curvature K·d² per sample, and the rulings of
// M^∞ (polylines where it is developable and curved). The three.js geometries are allocated once
// per topology (the patches' grid sizes, the control mesh's edges) and updated in place with every
// iterate; the rulings' buffer grows by doubling (their number changes from iterate to iterate).

import { BufferAttribute, BufferGeometry, DynamicDrawUsage } from 'three';
import { decodeArray, decodeArrayInto, elementCount } from './decode.js';
import { divergingColorAt, niceRange, srgbToLinear } from './colormap.js';
import { ensureFloatAttribute, markUpdated } from './StripBuffers.js';

/** Smallest legend range of K·d² (scale-free): a surface below it reads as developable (light). */
export const SPLINE_GAUSS_MIN_RANGE = 0.01;

/** The colour of M^∞ when it is not coloured by K·d² (sRGB; QuadMeshBuffers' paper). */
const PAPER = [0.86, 0.84, 0.79];

/**
 * Writes a line-segment position array (pairs of points of `points`, given by index pairs) into a
 * geometry, the attribute sized exactly. Returns whether the attribute was reallocated.
 */
export function setSegments(geometry, points, pairs, count) {
  const r = ensureFloatAttribute(geometry, 'position', Math.max(6, 6 * count), 3);
  const a = r.attribute.array;
  for (let k = 0; k < count; k++) {
    const i = pairs[2 * k], j = pairs[2 * k + 1];
    a[6 * k] = points[3 * i]; a[6 * k + 1] = points[3 * i + 1]; a[6 * k + 2] = points[3 * i + 2];
    a[6 * k + 3] = points[3 * j]; a[6 * k + 4] = points[3 * j + 1]; a[6 * k + 5] = points[3 * j + 2];
  }
  markUpdated(r.attribute);
  geometry.setDrawRange(0, 2 * count);
  geometry.computeBoundingSphere();
  return r.reallocated;
}

/** Triangles of row-major sample grids ({rows, columns} each, vertices numbered on): two per cell. */
export function gridTriangles(grids) {
  let cells = 0;
  let vertices = 0;
  for (const g of grids) {
    cells += Math.max(0, g.rows - 1) * Math.max(0, g.columns - 1);
    vertices += g.rows * g.columns;
  }
  const index = vertices > 65535 ? new Uint32Array(6 * cells) : new Uint16Array(6 * cells);
  let o = 0;
  let base = 0;
  for (const { rows, columns } of grids) {
    for (let r = 0; r + 1 < rows; r++) {
      for (let c = 0; c + 1 < columns; c++) {
        const a = base + r * columns + c, b = a + 1, d = a + columns, e = d + 1;
        index[o++] = a; index[o++] = b; index[o++] = e;
        index[o++] = a; index[o++] = e; index[o++] = d;
      }
    }
    base += rows * columns;
  }
  return index;
}

/** Segment count of encoded polylines ({shape: [n, 3]}): n − 1 each. */
export function polylineSegmentCount(polylines) {
  let n = 0;
  for (const p of polylines) n += Math.max(0, p.shape[0] - 1);
  return n;
}

/** A float attribute holding at least `length` floats (kept when large enough, else doubled). */
function ensureCapacity(geometry, name, length, itemSize) {
  const existing = geometry.getAttribute(name);
  if (existing && existing.array.length >= length) return { attribute: existing, reallocated: false };
  let capacity = existing ? existing.array.length : 6 * itemSize;
  while (capacity < length) capacity *= 2;
  if (existing) geometry.dispose();
  const attribute = new BufferAttribute(new Float32Array(capacity), itemSize).setUsage(DynamicDrawUsage);
  geometry.setAttribute(name, attribute);
  return { attribute, reallocated: true };
}

export class SplineBuffers {
  constructor() {
    /** M^∞: the patches' sample grids as indexed triangles (position, normal, color). */
    this.surface = new BufferGeometry();
    /** The control mesh's edges (LineSegments). */
    this.controlLines = new BufferGeometry();
    /** The rulings of M^∞ (LineSegments, consecutive points of each polyline). */
    this.rulings = new BufferGeometry();
    /** Whether the last geometry carried a spline. */
    this.present = false;
    /** Control points M [P·3] and the control mesh's edges [E·2]. */
    this.control = new Float32Array(0);
    this.controlEdges = new Int32Array(0);
    /** Subdivision rounds k of S^k(M). */
    this.rounds = 0;
    /** Per patch: {rows, columns, first (index of its first sample)}. */
    this.patches = [];
    /** K·d² per sample, all patches in order [N]. */
    this.gauss = new Float32Array(0);
    /** Number of ruling polylines and of drawn ruling segments. */
    this.rulingCount = 0;
    this.rulingSegments = 0;
    this.gaussMaxScaled = 0;
    this.gaussMeanScaled = 0;
    this.sharedSides = 0;
    this.normalJumpMaxDeg = 0;
    /** Colouring: whether M^∞ is coloured by K·d², the legend range and the drawn max |K·d²|. */
    this.colored = false;
    this.colorRange = SPLINE_GAUSS_MIN_RANGE;
    this.colorMax = 0;
    this.version = 0;
    this._gridKey = '';
    this._edgesText = null;
    this._targets = [];
    /** One decoded ruling polyline at a time (grown to the longest). */
    this._polyline = new Float32Array(0);
  }

  get controlCount() {
    return this.control.length / 3;
  }

  get sampleCount() {
    return this.gauss.length;
  }

  get patchCount() {
    return this.patches.length;
  }

  /** Targets of the control points: {vertex, on: 'control'}. */
  targets() {
    return this._targets;
  }

  /** Applies a geometry's `spline` object (or null/undefined: no spline); returns true when a buffer was reallocated. */
  apply(s) {
    if (!s) return this._clear();
    this.present = true;
    const length = elementCount(s.control);
    if (s.control.shape[1] !== 3) throw new Error(`spline: control has shape [${s.control.shape}], expected [P, 3]`);
    if (this.control.length !== length) this.control = new Float32Array(length);
    decodeArrayInto(s.control, this.control);
    const P = this.controlCount;
    if (s.control_edges.data !== this._edgesText) {
      this.controlEdges = decodeArray(s.control_edges).data;
      this._edgesText = s.control_edges.data;
    }
    for (let k = 0; k < this.controlEdges.length; k++) {
      if (this.controlEdges[k] < 0 || this.controlEdges[k] >= P) throw new Error(`spline: control edge ${k >> 1} refers to control point ${this.controlEdges[k]} of ${P}`);
    }
    if (this._targets.length !== P) this._targets = Array.from({ length: P }, (_, i) => ({ vertex: i, on: 'control' }));
    this.rounds = s.rounds | 0;
    this.gaussMaxScaled = Number(s.gauss_max_scaled) || 0;
    this.gaussMeanScaled = Number(s.gauss_mean_scaled) || 0;
    this.sharedSides = s.shared_sides | 0;
    this.normalJumpMaxDeg = Number(s.normal_jump_max_deg) || 0;
    let realloc = this._fillSurface(s.patches || []);
    realloc = setSegments(this.controlLines, this.control, this.controlEdges, this.controlEdges.length / 2) || realloc;
    realloc = this._fillRulings(s.rulings || []) || realloc;
    this._recolor();
    this.version++;
    return realloc;
  }

  _clear() {
    const was = this.present;
    this.present = false;
    this.control = new Float32Array(0);
    this.controlEdges = new Int32Array(0);
    this._edgesText = null;
    this._targets = [];
    this.patches = [];
    this.gauss = new Float32Array(0);
    this.rulingCount = 0;
    this.rulingSegments = 0;
    for (const g of [this.surface, this.controlLines, this.rulings]) g.setDrawRange(0, 0);
    if (was) this.version++;
    return was;
  }

  _fillSurface(patches) {
    const key = patches.map((p) => `${p.rows}x${p.columns}`).join(',');
    let N = 0;
    this.patches = patches.map((p) => {
      const n = p.rows * p.columns;
      if (!(n > 0) || elementCount(p.points) !== 3 * n || elementCount(p.gauss_scaled) !== n) {
        throw new Error(`spline: patch of ${p.rows} × ${p.columns} samples has ${elementCount(p.points) / 3} points and ${elementCount(p.gauss_scaled)} curvatures`);
      }
      const entry = { rows: p.rows, columns: p.columns, first: N };
      N += n;
      return entry;
    });
    const pos = ensureFloatAttribute(this.surface, 'position', Math.max(3, 3 * N), 3);
    let realloc = pos.reallocated;
    if (realloc) {
      this.surface.deleteAttribute('normal');
      this.surface.deleteAttribute('color');
    }
    if (key !== this._gridKey || realloc) {
      this.surface.setIndex(new BufferAttribute(gridTriangles(this.patches), 1));
      this._gridKey = key;
      realloc = true;
    }
    if (this.gauss.length !== N) this.gauss = new Float32Array(N);
    for (const [k, p] of patches.entries()) {
      const { first } = this.patches[k];
      const n = p.rows * p.columns;
      decodeArrayInto(p.points, pos.attribute.array.subarray(3 * first, 3 * (first + n)));
      decodeArrayInto(p.gauss_scaled, this.gauss.subarray(first, first + n));
    }
    markUpdated(pos.attribute);
    this.surface.setDrawRange(0, this.surface.index.count);
    // Smooth shading: M^∞ is a smooth surface (its patches meet with their own normals).
    this.surface.computeVertexNormals();
    markUpdated(this.surface.getAttribute('normal'));
    this.surface.computeBoundingSphere();
    return realloc;
  }

  _fillRulings(polylines) {
    let longest = 0;
    for (const r of polylines) {
      if (r.shape.length !== 2 || r.shape[1] !== 3) throw new Error(`spline: a ruling has shape [${r.shape}], expected [n, 3]`);
      longest = Math.max(longest, 3 * r.shape[0]);
    }
    if (this._polyline.length < longest) this._polyline = new Float32Array(longest);
    const S = polylineSegmentCount(polylines);
    const attr = ensureCapacity(this.rulings, 'position', 6 * S, 3);
    const a = attr.attribute.array;
    let o = 0;
    for (const r of polylines) {
      const p = decodeArrayInto(r, this._polyline.subarray(0, 3 * r.shape[0]));
      for (let i = 0; i + 5 < p.length; i += 3) {
        for (let c = 0; c < 6; c++) a[o + c] = p[i + c];
        o += 6;
      }
    }
    const pa = attr.attribute;
    pa.clearUpdateRanges();
    pa.addUpdateRange(0, Math.max(o, 1));
    pa.needsUpdate = true;
    this.rulings.setDrawRange(0, 2 * S);
    this.rulings.computeBoundingSphere();
    this.rulingCount = polylines.length;
    this.rulingSegments = S;
    return attr.reallocated;
  }

  /** Colours M^∞ by K·d² (a diverging map centred at 0) or plain paper; returns whether it changed. */
  setColored(colored) {
    if (colored === this.colored) return false;
    this.colored = colored;
    if (this.present) this._recolor();
    return true;
  }

  _recolor() {
    const N = this.sampleCount;
    let max = 0;
    for (let i = 0; i < N; i++) {
      const v = Math.abs(this.gauss[i]);
      if (v > max && Number.isFinite(v)) max = v;
    }
    this.colorMax = max;
    this.colorRange = niceRange(max, SPLINE_GAUSS_MIN_RANGE);
    const col = ensureFloatAttribute(this.surface, 'color', Math.max(3, 3 * N), 3).attribute;
    const a = col.array;
    const c = PAPER.slice();
    for (let i = 0; i < N; i++) {
      if (this.colored) divergingColorAt(this.gauss[i] / this.colorRange, c, 0);
      // three.js vertex colours are linear.
      a[3 * i] = srgbToLinear(c[0]);
      a[3 * i + 1] = srgbToLinear(c[1]);
      a[3 * i + 2] = srgbToLinear(c[2]);
    }
    markUpdated(col);
  }

  /** [x, y, z] of control point i, or null. */
  controlPoint(i) {
    if (!Number.isInteger(i) || i < 0 || i >= this.controlCount) return null;
    return [this.control[3 * i], this.control[3 * i + 1], this.control[3 * i + 2]];
  }

  dispose() {
    for (const g of [this.surface, this.controlLines, this.rulings]) g.dispose();
  }
}
