// Buffers for a quad_mesh session's geometry (proto/include/devsurf/proto/Geometry.h,
// quadMeshGeometryJson): the mesh M (3D) and its unfolding M′, updated from every `geometry`
// message. M is drawn by the 3D view from three.js geometries kept here (faces split into
// triangles with flat normals and per-face colours, wireframe edges with per-edge colours,
// rulings, glue links); M′ is drawn by the 2D unfolding view from the typed arrays and the
// per-face / per-edge colours computed here, so both views always show the same colour mode:
//   length_error  |l′ − l|/l per edge on the edges of M and M′ (faces plain paper),
//   gauss, mean   K or H per face (diverging map centred at 0; needs the Gauss image),
//   spline_gauss  K·d² of the limit surface M^∞ (spline sessions only; M and M′ plain).
// A scene with a control net (issue 14) also carries `spline`: its buffers are `this.spline`
// (SplineBuffers). Its control points are then draggable targets {vertex, on: 'control'} and,
// while the limit surface M^∞ is the surface shown (`display`), the only ones in the 3D view.

import { BufferGeometry } from 'three';
import { decodeArray } from './decode.js';
import { colorAt, divergingColorAt, niceRange, srgbToLinear } from './colormap.js';
import { ensureFloatAttribute, markUpdated } from './StripBuffers.js';
import { SplineBuffers, setSegments } from './SplineBuffers.js';
import { targetOf } from '../commands/Command.js';

/** Colour modes of a quad mesh: what is coloured, the legend and whether curvature is needed. */
export const QUAD_COLOR_MODES = {
  length_error: { label: 'L-Err per edge', title: 'edge length error |l′ − l|/l', unit: '%', scale: 100, perEdge: true, diverging: false, needsCurvature: false },
  gauss: { label: 'K (Gauss)', title: 'Gauss curvature K', unit: '', scale: 1, perEdge: false, diverging: true, needsCurvature: true, field: 'gauss' },
  mean: { label: 'H (mean)', title: 'mean curvature H', unit: '', scale: 1, perEdge: false, diverging: true, needsCurvature: true, field: 'mean' },
  spline_gauss: { label: 'K·d² (limit)', title: 'K·d² of the limit surface', unit: '', scale: 1, perEdge: false, diverging: true, needsCurvature: false, spline: true },
};

/** What the 3D view shows of a spline session: the limit surface M^∞ or the refined mesh S^k(M). */
export const SPLINE_DISPLAYS = {
  limit: { label: 'limit surface', title: 'The spline surface itself (its patches sampled), its rulings and the control net' },
  refined: { label: 'refined Sᵏ(M)', title: 'The refined mesh the solver optimizes (its faces, edges and vertices) and the control net' },
};

/** Sprite colour of the control points of a spline surface. */
export const CONTROL_POINT_COLOR = 0x7fd4ff;

/** sRGB colours of the neutral drawing (faces without a field, edges over coloured faces). */
export const QUAD_PAPER = [0.86, 0.84, 0.79];
export const QUAD_EDGE = [0.38, 0.4, 0.44];
export const QUAD_BOUNDARY_EDGE = [0.06, 0.06, 0.08];

/** Whether a geometry message is a quad_mesh's (by kind, or by its fields when kind is absent). */
export function isQuadMeshGeometry(g) {
  if (!g || typeof g !== 'object') return false;
  if (g.kind !== undefined) return g.kind === 'quad_mesh';
  return !!(g.mesh && g.unfolding && g.faces && g.edges);
}

/** Faces [F·4] (−1 in column 3 for a triangle) → triangles [T·3] and the face of each triangle. */
export function triangulateFaces(faces) {
  const F = faces.length / 4;
  let T = 0;
  for (let f = 0; f < F; f++) T += faces[4 * f + 3] >= 0 ? 2 : 1;
  const triangles = new Int32Array(3 * T);
  const triFace = new Int32Array(T);
  let t = 0;
  for (let f = 0; f < F; f++) {
    const a = faces[4 * f], b = faces[4 * f + 1], c = faces[4 * f + 2], d = faces[4 * f + 3];
    triangles.set([a, b, c], 3 * t);
    triFace[t++] = f;
    if (d >= 0) {
      triangles.set([a, c, d], 3 * t);
      triFace[t++] = f;
    }
  }
  return { triangles, triFace };
}

/** Per vertex: 1 when it is an end point of a boundary edge (edge_boundary = 1). */
export function boundaryVertexFlags(edges, edgeBoundary, vertexCount) {
  const flags = new Uint8Array(vertexCount);
  for (let e = 0; e < edgeBoundary.length; e++) {
    if (edgeBoundary[e]) {
      flags[edges[2 * e]] = 1;
      flags[edges[2 * e + 1]] = 1;
    }
  }
  return flags;
}

/** Largest |v| over finite values. */
export function maxAbs(values) {
  let m = 0;
  for (let i = 0; i < values.length; i++) {
    const a = Math.abs(values[i]);
    if (a > m && Number.isFinite(a)) m = a;
  }
  return m;
}

const linear = (c, out, o) => {
  out[o] = srgbToLinear(c[0]);
  out[o + 1] = srgbToLinear(c[1]);
  out[o + 2] = srgbToLinear(c[2]);
};

export class QuadMeshBuffers {
  constructor() {
    this.kind = 'quad_mesh';
    /** M's faces as triangles (non-indexed: position, normal, color). */
    this.surface = new BufferGeometry();
    /** M's edges: LineSegments with per-vertex colours. */
    this.edgeLines = new BufferGeometry();
    /** Ruling segments of the developable faces (curvature.rulings). */
    this.rulings = new BufferGeometry();
    /** Glued pairs (both lists) as segments between the two vertices of M. */
    this.glueLines = new BufferGeometry();
    this.mesh = new Float32Array(0);
    this.unfolding = new Float32Array(0);
    this.faces = new Int32Array(0);
    this.edges = new Int32Array(0);
    this.edgeBoundary = new Int32Array(0);
    this.edgeLengthError = new Float32Array(0);
    this.faceAreaError = new Float32Array(0);
    /** Glued vertex pairs [G·2] on M and [G′·2] on M′. */
    this.glue = new Int32Array(0);
    this.glueUnfolding = new Int32Array(0);
    this.variable = 'mesh';
    this.planar = true;
    this.conformal = false;
    /** null, or {gauss, mean, kappa1, kappa2 [F], rulings [F·6]}. */
    this.curvature = null;
    this.boundary = new Uint8Array(0);
    this.glued = new Uint8Array(0);
    this.triangles = new Int32Array(0);
    this.triFace = new Int32Array(0);
    this.colorMode = 'length_error';
    this.colorRange = 1;
    this.colorMax = 0;
    /** sRGB per face [F·3] and per edge [E·3] of the current mode (the 2D view uses them). */
    this.faceColors = new Float32Array(0);
    this.edgeColors = new Float32Array(0);
    /** Length of M's bounding-box diagonal (curvature scales). */
    this.diagonal = 1;
    this.version = 0;
    this.hasData = false;
    /** The limit surface M^∞ and control net of a spline session (spline.present), issue 14. */
    this.spline = new SplineBuffers();
    /** 'limit' | 'refined': which surface the 3D view shows when there is a spline. */
    this.display = 'limit';
    this._facesText = null;
    this._targets = [];
    this._allTargets = [];
  }

  get vertexCount() {
    return this.mesh.length / 3;
  }

  get faceCount() {
    return this.faces.length / 4;
  }

  get edgeCount() {
    return this.edges.length / 2;
  }

  get hasCurvature() {
    return !!this.curvature;
  }

  /** Whether the geometry carries a spline surface (a control net). */
  get hasSpline() {
    return this.spline.present;
  }

  /** Whether the 3D view shows the limit surface M^∞ (a spline session in display 'limit'). */
  get showsLimit() {
    return this.spline.present && this.display === 'limit';
  }

  /** Whether M′ has variables (its vertices can be dragged). */
  get unfoldingVariable() {
    return this.variable === 'unfolding' || this.variable === 'both';
  }

  /** Whether M has variables. */
  get meshVariable() {
    return this.variable === 'mesh' || this.variable === 'both';
  }

  /** Applies one quad_mesh geometry object; returns true when a buffer was reallocated. */
  apply(g) {
    if (!isQuadMeshGeometry(g)) throw new Error(`unsupported geometry kind ${g && g.kind}`);
    this.mesh = decodeArray(g.mesh).data;
    this.unfolding = decodeArray(g.unfolding).data;
    const V = this.vertexCount;
    if (this.unfolding.length !== 3 * V) throw new Error(`quad_mesh geometry: unfolding has ${this.unfolding.length / 3} vertices, mesh ${V}`);
    if (g.faces.data !== this._facesText) {
      this.faces = decodeArray(g.faces).data;
      const { triangles, triFace } = triangulateFaces(this.faces);
      this.triangles = triangles;
      this.triFace = triFace;
      this._facesText = g.faces.data;
    }
    this.edges = decodeArray(g.edges).data;
    this.edgeBoundary = decodeArray(g.edge_boundary).data;
    this.edgeLengthError = decodeArray(g.edge_length_error).data;
    this.faceAreaError = g.face_area_error ? decodeArray(g.face_area_error).data : new Float32Array(this.faceCount);
    this.glue = g.glue ? decodeArray(g.glue).data : new Int32Array(0);
    this.glueUnfolding = g.glue_unfolding ? decodeArray(g.glue_unfolding).data : new Int32Array(0);
    this.variable = g.variable || 'mesh';
    this.planar = g.planar !== false;
    this.conformal = !!g.conformal;
    const c = g.curvature;
    this.curvature = c ? {
      gauss: decodeArray(c.gauss).data,
      mean: decodeArray(c.mean).data,
      kappa1: c.kappa1 ? decodeArray(c.kappa1).data : null,
      kappa2: c.kappa2 ? decodeArray(c.kappa2).data : null,
      rulings: c.rulings ? decodeArray(c.rulings).data : new Float32Array(0),
    } : null;
    this.boundary = boundaryVertexFlags(this.edges, this.edgeBoundary, V);
    this.glued = new Uint8Array(V);
    for (const list of [this.glue, this.glueUnfolding]) for (const i of list) if (i < V) this.glued[i] = 1;
    if (this._targets.length !== V) this._targets = Array.from({ length: V }, (_, i) => ({ vertex: i }));
    this._diagonal();
    const hadSpline = this.spline.present;
    const splineRealloc = this.spline.apply(g.spline);
    if (splineRealloc || hadSpline !== this.spline.present || this._allTargets.length !== V + this.spline.controlCount) this._joinTargets();

    let realloc = this._fillSurface();
    realloc = setSegments(this.edgeLines, this.mesh, this.edges, this.edgeCount) || realloc;
    realloc = this._fillRulings() || realloc;
    const pairs = new Int32Array(this.glue.length + this.glueUnfolding.length);
    pairs.set(this.glue);
    pairs.set(this.glueUnfolding, this.glue.length);
    realloc = setSegments(this.glueLines, this.mesh, pairs, pairs.length / 2) || realloc;
    // Without a spline the spline's colour mode has nothing to show: back to L-Err.
    if (!this.spline.present && this.colorInfo.spline) this.colorMode = 'length_error';
    this._recolor();
    this.version++;
    this.hasData = true;
    return realloc || splineRealloc;
  }

  /** Control points first (they win a pick), then the vertices of M. */
  _joinTargets() {
    this._allTargets = [...this.spline.targets(), ...this._targets];
  }

  /** 'limit' | 'refined' (spline sessions); returns whether it changed. */
  setDisplay(display) {
    if (!SPLINE_DISPLAYS[display] || display === this.display) return false;
    this.display = display;
    return true;
  }

  _diagonal() {
    const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
    const p = this.mesh;
    for (let i = 0; i < p.length; i += 3) {
      for (let c = 0; c < 3; c++) {
        if (p[i + c] < lo[c]) lo[c] = p[i + c];
        if (p[i + c] > hi[c]) hi[c] = p[i + c];
      }
    }
    const d = Math.hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]);
    this.diagonal = d > 0 && Number.isFinite(d) ? d : 1;
  }

  _fillSurface() {
    const T = this.triFace.length;
    const pos = ensureFloatAttribute(this.surface, 'position', Math.max(9, 9 * T), 3);
    if (pos.reallocated) this.surface.deleteAttribute('normal');
    const a = pos.attribute.array;
    const m = this.mesh;
    for (let k = 0; k < 3 * T; k++) {
      const v = this.triangles[k];
      a[3 * k] = m[3 * v]; a[3 * k + 1] = m[3 * v + 1]; a[3 * k + 2] = m[3 * v + 2];
    }
    markUpdated(pos.attribute);
    this.surface.setDrawRange(0, 3 * T);
    // Flat shading: every triangle keeps its own normal (the faces of a quad mesh are what it is).
    this.surface.computeVertexNormals();
    markUpdated(this.surface.getAttribute('normal'));
    this.surface.computeBoundingSphere();
    return pos.reallocated;
  }

  _fillRulings() {
    const r = this.curvature ? this.curvature.rulings : new Float32Array(0);
    const F = r.length / 6;
    const attr = ensureFloatAttribute(this.rulings, 'position', Math.max(6, r.length), 3);
    const a = attr.attribute.array;
    let n = 0;
    for (let f = 0; f < F; f++) {
      const o = 6 * f;
      if (Math.hypot(r[o + 3] - r[o], r[o + 4] - r[o + 1], r[o + 5] - r[o + 2]) <= 0) continue;
      for (let c = 0; c < 6; c++) a[6 * n + c] = r[o + c];
      n++;
    }
    markUpdated(attr.attribute);
    this.rulings.setDrawRange(0, 2 * n);
    this.rulings.computeBoundingSphere();
    this.rulingCount = n;
    return attr.reallocated;
  }

  /** 'length_error' | 'gauss' | 'mean' | 'spline_gauss' (with a spline); returns whether it changed. */
  setColorMode(mode) {
    if (!QUAD_COLOR_MODES[mode] || mode === this.colorMode) return false;
    if (QUAD_COLOR_MODES[mode].spline && this.hasData && !this.spline.present) return false;
    this.colorMode = mode;
    if (this.hasData) this._recolor();
    return true;
  }

  get colorInfo() {
    return QUAD_COLOR_MODES[this.colorMode];
  }

  /** The values coloured in the current mode (per edge or per face), or null (no curvature yet, or M^∞'s). */
  colorValues() {
    const info = this.colorInfo;
    if (info.spline) return null;
    if (info.perEdge) return this.edgeLengthError;
    return this.curvature ? this.curvature[info.field] : null;
  }

  /** Smallest legend range: curvature scales with the mesh (K ~ 1/size², H ~ 1/size). */
  _minRange() {
    if (this.colorMode === 'gauss') return 1e-2 / (this.diagonal * this.diagonal);
    if (this.colorMode === 'mean') return 1e-2 / this.diagonal;
    return 1e-4;
  }

  _recolor() {
    const info = this.colorInfo;
    const F = this.faceCount, E = this.edgeCount;
    if (this.faceColors.length !== 3 * F) this.faceColors = new Float32Array(3 * F);
    if (this.edgeColors.length !== 3 * E) this.edgeColors = new Float32Array(3 * E);
    const values = this.colorValues();
    this.spline.setColored(!!info.spline);
    if (info.spline) {
      // K·d² of M^∞ (SplineBuffers colours its samples); M and M′ stay plain paper.
      this.colorMax = this.spline.colorMax;
      this.colorRange = this.spline.colorRange;
    } else {
      this.colorMax = values ? maxAbs(values) : 0;
      this.colorRange = niceRange(this.colorMax, this._minRange());
    }
    const fc = this.faceColors, ec = this.edgeColors;
    for (let f = 0; f < F; f++) {
      if (info.perEdge || !values) fc.set(QUAD_PAPER, 3 * f);
      else divergingColorAt(values[f] / this.colorRange, fc, 3 * f);
    }
    for (let e = 0; e < E; e++) {
      if (info.perEdge) colorAt(Math.abs(values[e]) / this.colorRange, ec, 3 * e);
      else ec.set(this.edgeBoundary[e] ? QUAD_BOUNDARY_EDGE : QUAD_EDGE, 3 * e);
    }
    // three.js vertex colours are linear.
    const T = this.triFace.length;
    const sc = ensureFloatAttribute(this.surface, 'color', Math.max(9, 9 * T), 3).attribute;
    for (let t = 0; t < T; t++) {
      const f = this.triFace[t];
      for (let k = 0; k < 3; k++) linear(fc.subarray(3 * f, 3 * f + 3), sc.array, 9 * t + 3 * k);
    }
    markUpdated(sc);
    const lc = ensureFloatAttribute(this.edgeLines, 'color', Math.max(6, 6 * E), 3).attribute;
    for (let e = 0; e < E; e++) {
      const c = ec.subarray(3 * e, 3 * e + 3);
      linear(c, lc.array, 6 * e);
      linear(c, lc.array, 6 * e + 3);
    }
    markUpdated(lc);
  }

  /**
   * Targets of the draggable points of the 3D view: every vertex of M; with a spline its control
   * points too (first), and only them while the limit surface is shown.
   */
  pointTargets() {
    if (!this.spline.present) return this._targets;
    return this.display === 'limit' ? this.spline.targets() : this._allTargets;
  }

  /** How many points the 3D view's point size is chosen for (the control points of a spline). */
  pointDensityCount() {
    return this.spline.present ? this.spline.controlCount : this.vertexCount;
  }

  /** Picking priority: a control point wins over a vertex of M under the pointer. */
  pickPriority(item) {
    return item.on === 'control' ? 1 : 0;
  }

  /** [x, y, z] of {vertex} (M), {vertex, on: 'unfolding'} (M′) or {vertex, on: 'control'}, or null. */
  pointOf(t) {
    const x = targetOf(t);
    if (x && x.on === 'control') return this.spline.controlPoint(x.vertex);
    if (!x || x.vertex === undefined || x.vertex >= this.vertexCount) return null;
    const p = x.on === 'unfolding' ? this.unfolding : this.mesh;
    const i = 3 * x.vertex;
    return [p[i], p[i + 1], p[i + 2]];
  }

  isBoundary(i) {
    return this.boundary[i] === 1;
  }

  /** Sprite colour of a vertex of M in the 3D view (glued vertices green, boundary ones warm). */
  pointColor(item) {
    const i = item.vertex;
    if (item.on === 'control') return CONTROL_POINT_COLOR;
    if (this.glued[i]) return 0x5ee6a0;
    if (this.boundary[i]) return 0xffd9b0;
    return 0xf4f6f8;
  }

  /** Sprite size factor: interior vertices small (still picked within the view's tolerance). */
  pointScale(item) {
    const i = item.vertex;
    if (item.on === 'control') return 1;
    if (this.glued[i]) return 1;
    // Next to a control net the vertices of S^k(M) are secondary: smaller than the control points.
    if (this.spline.present) return this.boundary[i] ? 0.6 : 0.4;
    return this.boundary[i] ? 1 : 0.6;
  }

  dispose() {
    for (const g of [this.surface, this.edgeLines, this.rulings, this.glueLines]) g.dispose();
    this.spline.dispose();
  }
}
