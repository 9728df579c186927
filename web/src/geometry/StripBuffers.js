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

/** The protocol's curve names per geometry kind; the buffers keep them in slots a and b. */
export const CURVE_NAMES = { strip: ['a', 'b'], quasi_strip: ['c1', 'c2'], conical_strip: ['p', 'q'] };

/** Colours of conical patch types (patch_type 3 = triangular, 4 = quadrilateral), linear RGB. */
export const PATCH_TYPE_COLORS = { 3: [0.96, 0.62, 0.26], 4: [0.24, 0.6, 0.72] };

/** Colour fields of conical strips ({title, unit} for the legend). */
export const CONICAL_COLOR_MODES = {
  normal_jump: { title: 'normal jump', unit: '°' },
  patch_type: { title: 'patch type', unit: '' },
};

/**
 * Buffers of the ruled strips: Tang et al.'s strip ("strip"), Bo et al.'s quasi-developable strip
 * ("quasi_strip": coloured by warp angle, with the mapping σ) and Chu et al.'s conical strip
 * ("conical_strip": patches coloured by normal jump or patch type, unfolded patches).
 */
export class StripBuffers {
  constructor() {
    this.kind = 'strip';
    /** The geometry kind applied last, and its curve names (slot a, slot b). */
    this.modelKind = 'strip';
    this.curveNames = CURVE_NAMES.strip;
    /** Conical strips: 'normal_jump' | 'patch_type'. */
    this.colorMode = 'normal_jump';
    this.colorInfo = { title: 'warp angle', unit: '°' };
    /** Conical strips: per patch {type: Int32Array (3|4), jump: Float32Array (deg), base: 'PQ…'} or null. */
    this.patches = null;
    /** Quasi strips: {sigma, initial: Float32Array [t, σ] pairs, samples, trim, domainC1, domainC2} or null. */
    this.mapping = null;
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
    if (!g || !CURVE_NAMES[g.kind]) throw new Error(`unsupported geometry kind ${g && g.kind}`);
    if (!g.surface) throw new Error(`${g.kind} geometry without a surface (not solved)`);
    let realloc = false;
    this._last = g;
    if (g.kind !== this.modelKind) realloc = true;
    this.modelKind = g.kind;
    this.curveNames = CURVE_NAMES[g.kind];
    const conical = g.kind === 'conical_strip';
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

    // Warp angle (conical strips: normal jump or patch type) → vertex colours.
    const field = conical ? (this.colorMode === 'patch_type' ? s.patch_type : s.normal_jump_deg) : s.warp_angle_deg;
    this.colorInfo = conical ? CONICAL_COLOR_MODES[this.colorMode] : { title: 'warp angle', unit: '°' };
    this.categorical = conical && this.colorMode === 'patch_type';
    if (field) {
      this.warp = sized(this.warp, Float32Array, elementCount(field));
      decodeArrayInto(field, this.warp);
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
    if (this.categorical) {
      const out = color.attribute.array;
      for (let i = 0; i < this.warp.length; i++) out.set(PATCH_TYPE_COLORS[this.warp[i]] || [0.6, 0.6, 0.6], 3 * i);
    } else {
      fillColors(this.warp, color.attribute.array, this.colorRange);
    }
    markUpdated(color.attribute);

    this.surface.computeVertexNormals();
    markUpdated(this.surface.getAttribute('normal'));
    this.surface.computeBoundingSphere();
    this.surface.computeBoundingBox();

    // Curves and control polygons.
    ['a', 'b'].forEach((c, slot) => {
      const name = this.curveNames[slot];
      if (g.curves && g.curves[name]) {
        const r = updateFloatAttribute(this.curves[c], 'position', g.curves[name], 3);
        realloc = r.reallocated || realloc;
        this._setLoop(this.curves[c], g.curves[name].shape[0], r.reallocated);
      }
      if (g.control_points && g.control_points[name]) {
        const r = updateFloatAttribute(this.polygons[c], 'position', g.control_points[name], 3);
        realloc = r.reallocated || realloc;
        this.controlPoints[c] = r.attribute.array;
        this._setLoop(this.polygons[c], g.control_points[name].shape[0], r.reallocated);
        this.polygons[c].computeBoundingSphere();
      }
    });

    // Conical patches (per patch type and normal jump) and the quasi strip's mapping σ.
    if (conical && g.patches) {
      const type = new Int32Array(elementCount(g.patches.type));
      decodeArrayInto(g.patches.type, type);
      const jump = new Float32Array(elementCount(g.patches.normal_jump_deg));
      decodeArrayInto(g.patches.normal_jump_deg, jump);
      this.patches = { type, jump, base: g.patches.base || '' };
    } else {
      this.patches = null;
    }
    if (g.kind === 'quasi_strip' && g.mapping) {
      const m = g.mapping;
      const decode = (spec) => {
        const out = new Float32Array(elementCount(spec));
        decodeArrayInto(spec, out);
        return out;
      };
      this.mapping = {
        sigma: decode(m.sigma), initial: decode(m.initial), samples: m.samples ? decode(m.samples) : new Float32Array(0),
        trim: m.trim, domainC1: m.domain_c1, domainC2: m.domain_c2,
      };
    } else {
      this.mapping = null;
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
      // Conical strips: the patch of every unfolded quad, and its colour value.
      if (d.quad_patch && this.patches) {
        const qp = new Int32Array(elementCount(d.quad_patch));
        decodeArrayInto(d.quad_patch, qp);
        const values = new Float32Array(qp.length);
        const source = this.categorical ? this.patches.type : this.patches.jump;
        for (let i = 0; i < qp.length; i++) values[i] = source[qp[i]] || 0;
        this.development.quadPatch = qp;
        this.development.quadValue = values;
      } else {
        this.development.quadPatch = null;
        this.development.quadValue = null;
      }
    } else {
      this.development.count = 0;
      this.development.quadPatch = null;
      this.development.quadValue = null;
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

  /** Re-colours the last geometry (conical strips: 'normal_jump' | 'patch_type'). */
  setColorMode(mode) {
    if (!CONICAL_COLOR_MODES[mode]) throw new TypeError(`unknown colour mode ${mode}`);
    this.colorMode = mode;
    if (this._last) this.apply(this._last);
  }

  /** Slot 'a' | 'b' of a curve name of the current kind (the slot names themselves too), or null. */
  slot(curve) {
    if (curve === 'a' || curve === 'b') return curve;
    const i = this.curveNames.indexOf(curve);
    return i < 0 ? null : ['a', 'b'][i];
  }

  /** Targets of every control point ({curve, index} with the kind's curve names, first curve first). */
  pointTargets() {
    const [first, second] = this.curveNames;
    const na = this.count('a'), nb = this.count('b');
    if (!this._targets || this._targets.length !== na + nb || this._targetsA !== na || this._targetsName !== first) {
      this._targets = [];
      for (const c of [first, second]) for (let i = 0; i < this.count(c); i++) this._targets.push({ curve: c, index: i });
      this._targetsA = na;
      this._targetsName = first;
    }
    return this._targets;
  }

  /** [x, y, z] of a target {curve, index}, or null. */
  pointOf(t) {
    return t && t.curve !== undefined ? this.point(t.curve, t.index) : null;
  }

  /** Number of control points of a curve (name or slot). */
  count(curve) {
    const p = this.controlPoints[this.slot(curve)];
    return p ? p.length / 3 : 0;
  }

  /** [x, y, z] of a control point, or null. */
  point(curve, index) {
    const p = this.controlPoints[this.slot(curve)];
    if (!p || index < 0 || 3 * index + 2 >= p.length) return null;
    return [p[3 * index], p[3 * index + 1], p[3 * index + 2]];
  }

  dispose() {
    for (const g of [this.surface, this.curves.a, this.curves.b, this.polygons.a, this.polygons.b, this.rulings, this.normals]) g.dispose();
  }
}
