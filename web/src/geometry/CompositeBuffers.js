// Buffers for a composite's geometry (docs/protocol.md "A composite's geometry"), updated in
// place from each `geometry` message like StripBuffers: the merged face mesh coloured by face
// flatness or vertex curvature, the edges sorted into line sets by their fold assignment
// (mountain, valley, flat interior, boundary), the S edges' control polygons, the draggable points
// with their protocol targets, and the development (crease pattern) for the 2D view.

import { BufferAttribute, BufferGeometry } from 'three';
import { decodeArray, decodeArrayInto, elementCount } from './decode.js';
import { fillColors, niceRange } from './colormap.js';
import { ensureFloatAttribute, markUpdated, quadsToTriangles, updateFloatAttribute } from './StripBuffers.js';
import { targetKey } from '../commands/Command.js';

/** Colour modes of a composite surface: the per-vertex field and its legend. */
export const COMPOSITE_COLOR_MODES = {
  flatness: { field: 'face_flatness', title: 'face flatness δ', unit: '', min: 1e-3 },
  curvature: { field: 'vertex_curvature', title: 'vertex curvature', unit: ' rad', min: 1e-3 },
};

/** Which line set an edge is drawn in. */
export function edgeLineSet(edge) {
  if (!edge.interior) return 'boundary';
  if (edge.assignment === 'M') return 'mountain';
  if (edge.assignment === 'V') return 'valley';
  return 'flat';
}

/** The protocol target of row k of `points.refs` ((vertex, edge, index) with −1 for unused). */
export function targetOfRef(refs, k) {
  const v = refs[3 * k];
  return v >= 0 ? { vertex: v } : { edge: refs[3 * k + 1], index: refs[3 * k + 2] };
}

/** Line-segment pairs of a polyline [k·3] appended to `out` (an array). */
function pushSegments(out, p) {
  for (let i = 0; i + 5 < p.length; i += 3) out.push(p[i], p[i + 1], p[i + 2], p[i + 3], p[i + 4], p[i + 5]);
}

function setPositions(geometry, values) {
  const r = ensureFloatAttribute(geometry, 'position', Math.max(values.length, 6), 3);
  r.attribute.array.fill(0);
  r.attribute.array.set(values);
  markUpdated(r.attribute);
  geometry.setDrawRange(0, values.length / 3);
  geometry.computeBoundingSphere();
  return r.reallocated;
}

export class CompositeBuffers {
  constructor() {
    this.kind = 'composite';
    this.surface = new BufferGeometry();
    /** Line sets: LineSegments geometries (pairs of points). */
    this.lines = {
      mountain: new BufferGeometry(), valley: new BufferGeometry(), flat: new BufferGeometry(),
      boundary: new BufferGeometry(), polygons: new BufferGeometry(),
    };
    /** Draggable points: positions [P·3] and their targets. */
    this.points = new Float32Array(0);
    this.targets = [];
    this._index = new Map();
    /** Per edge: {edge, v, type, crease, interior, assignment, midpoint, foldAngleDeg (mean), foldAngleMaxDeg (largest |·| along it), polyline}. */
    this.edges = [];
    this.fields = { face_flatness: new Float32Array(0), vertex_curvature: new Float32Array(0) };
    this.faceFlatness = new Float32Array(0);
    this.vertexCurvature = new Float32Array(0);
    this.colorMode = 'flatness';
    this.colorRange = niceRange(0, 1e-3);
    this.colorMax = 0;
    /** The crease pattern, or null: {vertices [M·2], count, triangles, triangleFace, edges [E·2], assignment, rulings [R·4]}. */
    this.development = null;
    this.version = 0;
    this.hasData = false;
    this._quadsText = null;
  }

  /** Applies one protocol geometry object of kind "composite". */
  apply(g) {
    if (!g || g.kind !== 'composite') throw new Error(`unsupported geometry kind ${g && g.kind}`);
    const s = g.surface;
    let realloc = updateFloatAttribute(this.surface, 'position', s.vertices, 3).reallocated;
    const n = s.vertices.shape[0];
    if (realloc || s.quads.data !== this._quadsText) {
      const quads = decodeArray(s.quads).data;
      this.surface.setIndex(new BufferAttribute(quadsToTriangles(quads, n), 1));
      this._quadsText = s.quads.data;
    }
    for (const name of Object.keys(this.fields)) {
      const spec = s[name];
      let a = this.fields[name];
      if (a.length !== n) a = this.fields[name] = new Float32Array(n);
      if (spec) decodeArrayInto(spec, a);
      else a.fill(0);
    }
    this.faceFlatness = g.face_flatness ? decodeArray(g.face_flatness).data : new Float32Array(0);
    this.vertexCurvature = g.vertex_curvature ? decodeArray(g.vertex_curvature).data : new Float32Array(0);
    this._recolor();
    this.surface.computeVertexNormals();
    markUpdated(this.surface.getAttribute('normal'));
    this.surface.computeBoundingSphere();

    // Edges and control polygons.
    const sets = { mountain: [], valley: [], flat: [], boundary: [], polygons: [] };
    this.edges = (g.edges || []).map((e) => {
      const polyline = decodeArray(e.polyline).data;
      pushSegments(sets[edgeLineSet(e)], polyline);
      if (e.control_points) pushSegments(sets.polygons, decodeArray(e.control_points).data);
      const k = polyline.length / 3;
      const m = Math.floor(k / 2);
      const midpoint = k % 2 === 1
        ? [polyline[3 * m], polyline[3 * m + 1], polyline[3 * m + 2]]
        : [0, 1, 2].map((c) => 0.5 * (polyline[3 * (m - 1) + c] + polyline[3 * m + c]));
      let fold = 0, largest = 0;
      if (e.fold_angle_deg) {
        const a = decodeArray(e.fold_angle_deg).data;
        for (const x of a) {
          fold += x;
          largest = Math.max(largest, Math.abs(x));
        }
        fold = a.length ? fold / a.length : 0;
      }
      return { edge: e.edge, v: e.v, type: e.type, crease: e.crease, interior: !!e.interior, assignment: e.assignment, midpoint, foldAngleDeg: fold, foldAngleMaxDeg: largest, polyline };
    });
    for (const [name, values] of Object.entries(sets)) realloc = setPositions(this.lines[name], values) || realloc;

    // Points.
    const pts = g.points;
    this.points = decodeArray(pts.positions).data;
    const refs = decodeArray(pts.refs).data;
    const count = pts.refs.shape[0];
    if (this.targets.length !== count || this._refsText !== pts.refs.data) {
      this.targets = Array.from({ length: count }, (_, k) => targetOfRef(refs, k));
      this._index = new Map(this.targets.map((t, k) => [targetKey(t), k]));
      this._refsText = pts.refs.data;
    }

    // Development.
    const d = g.development;
    if (d) {
      this.development = {
        vertices: decodeArray(d.vertices).data,
        count: d.vertices.shape[0],
        triangles: decodeArray(d.triangles).data,
        triangleFace: decodeArray(d.triangle_face).data,
        edges: decodeArray(d.edges).data,
        assignment: d.assignment || '',
        rulings: decodeArray(d.rulings).data,
      };
    } else {
      this.development = null;
    }
    this.version++;
    this.hasData = true;
    return realloc;
  }

  /** 'flatness' | 'curvature'. */
  setColorMode(mode) {
    if (!COMPOSITE_COLOR_MODES[mode] || mode === this.colorMode) return false;
    this.colorMode = mode;
    if (this.hasData) this._recolor();
    return true;
  }

  get colorInfo() {
    return COMPOSITE_COLOR_MODES[this.colorMode];
  }

  _recolor() {
    const info = this.colorInfo;
    const values = this.fields[info.field];
    let max = 0;
    for (let i = 0; i < values.length; i++) if (values[i] > max) max = values[i];
    this.colorMax = max;
    this.colorRange = niceRange(max, info.min);
    const color = ensureFloatAttribute(this.surface, 'color', values.length * 3, 3);
    fillColors(values, color.attribute.array, this.colorRange);
    markUpdated(color.attribute);
  }

  /** Targets of every draggable point (vertices first, then S-edge control points). */
  pointTargets() {
    return this.targets;
  }

  /** [x, y, z] of a target, or null. */
  pointOf(t) {
    const k = this._index.get(targetKey(t));
    if (k === undefined || 3 * k + 2 >= this.points.length) return null;
    return [this.points[3 * k], this.points[3 * k + 1], this.points[3 * k + 2]];
  }

  /** The edge record of edge e, or null. */
  edge(e) {
    return this.edges.find((x) => x.edge === e) || null;
  }

  dispose() {
    this.surface.dispose();
    for (const g of Object.values(this.lines)) g.dispose();
  }
}
