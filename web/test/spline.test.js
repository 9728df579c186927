import { describe, expect, it } from 'vitest';
import * as THREE from 'three';
import { SPLINE_GAUSS_MIN_RANGE, SplineBuffers, gridTriangles, polylineSegmentCount } from '../src/geometry/SplineBuffers.js';
import { CONTROL_POINT_COLOR, QUAD_PAPER, QuadMeshBuffers } from '../src/geometry/QuadMeshBuffers.js';
import { divergingColorAt, srgbToLinear } from '../src/geometry/colormap.js';
import {
  AddHandleCommand, DragCommand, DragEndCommand, PresenceCommand, RemoveHandleCommand, SetFixedCommand, sameTarget, targetKey, targetLabel, targetOf,
} from '../src/commands/index.js';
import { PointSprites, SHAPE_SPHERE } from '../src/view/PointSprites.js';
import { significant } from '../src/ui/QuadMeshControls.js';
import { f32, i32, validClient } from './helpers/proto.js';


/** A control net of 2 × 3 points; edges of its grid, each once. */
const CONTROL = [[0, 0, 0], [1, 0, 0], [2, 0, 0.5], [0, 1, 0], [1, 1, 0.25], [2, 1, 0.5]];
const CONTROL_EDGES = [[0, 1], [1, 2], [3, 4], [4, 5], [0, 3], [1, 4], [2, 5]];

/** A patch sampled on a rows × columns grid over [x0, x0 + 1] × [0, 1], z = lift·x, K·d² = gauss(r, c). */
function patch(rows, columns, x0, gauss = () => 0, lift = 0) {
  const points = [];
  const g = [];
  for (let r = 0; r < rows; r++) {
    for (let c = 0; c < columns; c++) {
      const x = x0 + c / (columns - 1);
      points.push([x, r / (rows - 1), lift * x]);
      g.push([gauss(r, c)]);
    }
  }
  return { rows, columns, points: f32(points, [rows * columns, 3]), gauss_scaled: f32(g, [rows * columns, 1]) };
}

/** The `spline` object of a geometry: two patches (3 × 4 and 3 × 3 samples), two rulings. */
function spline({ control = CONTROL, rulings = [[[0.5, 0, 0], [0.5, 0.5, 0], [0.5, 1, 0]], [[1.5, 0, 0], [1.5, 1, 0]]], shared = 1, gauss = (r, c) => (c - 1) * 0.125 } = {}) {
  return {
    control: f32(control, [control.length, 3]),
    control_edges: i32(CONTROL_EDGES, [CONTROL_EDGES.length, 2]),
    rounds: 2,
    patches: [patch(3, 4, 0, gauss), patch(3, 3, 1, (r, c) => -gauss(r, c) / 2, 0.5)],
    rulings: rulings.map((r) => f32(r, [r.length, 3])),
    gauss_max_scaled: 0.2,
    gauss_mean_scaled: 0.05,
    shared_sides: shared,
    normal_jump_max_deg: 1.25,
  };
}

/** A quad_mesh geometry (one quad, M′ flat) carrying a spline. */
function geometry(options = {}, withSpline = true) {
  const g = {
    kind: 'quad_mesh',
    mesh: f32([[0, 0, 0], [1, 0, 0], [1, 1, 0.25], [0, 1, 0]], [4, 3]),
    unfolding: f32([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], [4, 3]),
    faces: i32([[0, 1, 2, 3]], [1, 4]),
    edges: i32([[0, 1], [1, 2], [2, 3], [0, 3]], [4, 2]),
    edge_boundary: i32([[1], [1], [1], [1]], [4, 1]),
    edge_length_error: f32([[0], [0.01], [0], [0]], [4, 1]),
    glue: i32([], [0, 2]),
    glue_unfolding: i32([], [0, 2]),
    variable: 'both',
    planar: true,
    conformal: false,
    curvature: null,
  };
  if (withSpline) g.spline = spline(options);
  return g;
}

describe('spline surface buffers', () => {
  it('triangulates sample grids two triangles per cell, patch after patch', () => {
    const index = gridTriangles([{ rows: 2, columns: 3 }, { rows: 2, columns: 2 }]);
    expect(index).toBeInstanceOf(Uint16Array);
    expect(Array.from(index)).toEqual([0, 1, 4, 0, 4, 3, 1, 2, 5, 1, 5, 4, 6, 7, 9, 6, 9, 8]);
    expect(gridTriangles([{ rows: 300, columns: 300 }])).toBeInstanceOf(Uint32Array);
    expect(polylineSegmentCount([{ shape: [3, 3] }, { shape: [2, 3] }, { shape: [1, 3] }])).toBe(3);
  });

  it('fills the limit surface, the control net and the rulings from a synthetic spline', () => {
    const s = new SplineBuffers();
    expect(s.apply(spline())).toBe(true);
    expect(s.present).toBe(true);
    expect(s.controlCount).toBe(6);
    expect(s.patchCount).toBe(2);
    expect(s.sampleCount).toBe(21);
    expect(s.patches.map((p) => p.first)).toEqual([0, 12]);
    // M^∞: 2·3 + 2·2 cells, two triangles each.
    expect(s.surface.index.count).toBe(3 * 2 * (6 + 4));
    expect(s.surface.drawRange.count).toBe(60);
    const pos = s.surface.getAttribute('position').array;
    expect(pos.length).toBe(63);
    expect(Array.from(pos.slice(3 * 12, 3 * 13))).toEqual([1, 0, 0.5]);  // first sample of patch 2
    // Smooth normals of the flat first patch point along ±z.
    expect(Math.abs(s.surface.getAttribute('normal').array[2])).toBeCloseTo(1, 6);
    // Control net: 7 edges as 14 segment ends.
    expect(s.controlLines.drawRange.count).toBe(14);
    expect(Array.from(s.controlLines.getAttribute('position').array.slice(0, 6))).toEqual([0, 0, 0, 1, 0, 0]);
    // Rulings: polylines of 3 and 2 points → 2 + 1 segments.
    expect(s.rulingCount).toBe(2);
    expect(s.rulingSegments).toBe(3);
    expect(s.rulings.drawRange.count).toBe(6);
    expect(Array.from(s.rulings.getAttribute('position').array.slice(0, 12))).toEqual([0.5, 0, 0, 0.5, 0.5, 0, 0.5, 0.5, 0, 0.5, 1, 0]);
    expect(s.gaussMaxScaled).toBe(0.2);
    expect(s.gaussMeanScaled).toBe(0.05);
    expect(s.sharedSides).toBe(1);
    expect(s.normalJumpMaxDeg).toBe(1.25);
    expect(s.rounds).toBe(2);
    expect(s.controlPoint(4)).toEqual([1, 1, 0.25]);
    expect(s.controlPoint(6)).toBe(null);
    expect(s.targets()[5]).toEqual({ vertex: 5, on: 'control' });
  });

  it('updates in place per iterate and reallocates only for a new topology', () => {
    const s = new SplineBuffers();
    s.apply(spline());
    const pos = s.surface.getAttribute('position');
    const index = s.surface.index;
    const net = s.controlLines.getAttribute('position');
    const control = s.control;
    const moved = CONTROL.map((p, i) => (i === 4 ? [1, 1, 2] : p));
    expect(s.apply(spline({ control: moved }))).toBe(false);
    expect(s.control).toBe(control);
    expect(s.surface.getAttribute('position')).toBe(pos);
    expect(s.surface.index).toBe(index);
    expect(s.controlLines.getAttribute('position')).toBe(net);
    expect(s.controlPoint(4)).toEqual([1, 1, 2]);
    expect(s.version).toBe(2);
    // Fewer rulings: same buffer, shorter draw range; more than fit: the buffer grows.
    const rulings = s.rulings.getAttribute('position');
    expect(s.apply(spline({ rulings: [[[0, 0, 0], [0, 1, 0]]] }))).toBe(false);
    expect(s.rulings.getAttribute('position')).toBe(rulings);
    expect(s.rulings.drawRange.count).toBe(2);
    const many = Array.from({ length: 40 }, (_, k) => [[k / 40, 0, 0], [k / 40, 0.5, 0], [k / 40, 1, 0]]);
    expect(s.apply(spline({ rulings: many }))).toBe(true);
    expect(s.rulingSegments).toBe(80);
    expect(s.rulings.getAttribute('position').array.length).toBeGreaterThanOrEqual(480);
    // Another grid: a new index.
    const g = spline();
    g.patches = [patch(4, 4, 0)];
    expect(s.apply(g)).toBe(true);
    expect(s.surface.index.count).toBe(54);
    expect(s.sampleCount).toBe(16);
  });

  it('colours M^∞ by K·d² on the diverging map, or paper', () => {
    const s = new SplineBuffers();
    s.apply(spline());
    const colors = () => s.surface.getAttribute('color').array;
    const lin = (c) => c.map((v) => Math.fround(srgbToLinear(v)));
    expect(Array.from(colors().slice(0, 3))).toEqual(lin(QUAD_PAPER));
    expect(s.setColored(true)).toBe(true);
    expect(s.setColored(true)).toBe(false);
    // Samples of patch 1: K·d² = (c − 1)/8 → max |·| 0.25 at c = 3, range 0.25.
    expect(s.colorMax).toBe(0.25);
    expect(s.colorRange).toBeCloseTo(0.25, 9);
    expect(Array.from(colors().slice(0, 3))).toEqual(lin(divergingColorAt(-0.5, [0, 0, 0])));
    expect(Array.from(colors().slice(3, 6))).toEqual(lin(divergingColorAt(0, [0, 0, 0])));
    expect(Array.from(colors().slice(9, 12))).toEqual(lin(divergingColorAt(1, [0, 0, 0])));
    // A developable surface: the legend keeps its smallest range.
    s.apply(spline({ gauss: () => 1e-6 }));
    expect(s.colorRange).toBe(SPLINE_GAUSS_MIN_RANGE);
  });

  it('refuses inconsistent patches and edges', () => {
    const bad = spline();
    bad.patches[0].gauss_scaled = f32([[0]], [1, 1]);
    expect(() => new SplineBuffers().apply(bad)).toThrow(/patch of 3 × 4/);
    const edges = spline();
    edges.control_edges = i32([[0, 9]], [1, 2]);
    expect(() => new SplineBuffers().apply(edges)).toThrow(/control point 9/);
  });
});

describe('a quad_mesh geometry with a spline', () => {
  it('has the control points as targets: alone on the limit surface, first beside S^k(M)', () => {
    const q = new QuadMeshBuffers();
    q.apply(geometry());
    expect(q.hasSpline).toBe(true);
    expect(q.display).toBe('limit');
    expect(q.showsLimit).toBe(true);
    expect(q.pointTargets().map(targetKey)).toEqual(['m0', 'm1', 'm2', 'm3', 'm4', 'm5']);
    expect(q.pointDensityCount()).toBe(6);
    expect(q.pointOf({ vertex: 2, on: 'control' })).toEqual([2, 0, 0.5]);
    expect(q.pointOf({ vertex: 2 })).toEqual([1, 1, 0.25]);
    expect(q.pointColor({ vertex: 1, on: 'control' })).toBe(CONTROL_POINT_COLOR);
    expect(q.pickPriority({ vertex: 1, on: 'control' })).toBeGreaterThan(q.pickPriority({ vertex: 1 }));
    expect(q.setDisplay('refined')).toBe(true);
    expect(q.setDisplay('refined')).toBe(false);
    expect(q.setDisplay('nowhere')).toBe(false);
    expect(q.showsLimit).toBe(false);
    expect(q.pointTargets().map(targetKey)).toEqual(['m0', 'm1', 'm2', 'm3', 'm4', 'm5', 'v0', 'v1', 'v2', 'v3']);
  });

  it('colours by K·d² of M^∞ in the spline mode (M and M′ plain), and drops it without a spline', () => {
    const q = new QuadMeshBuffers();
    expect(q.setColorMode('spline_gauss')).toBe(true);
    q.apply(geometry());
    expect(q.colorMode).toBe('spline_gauss');
    expect(q.spline.colored).toBe(true);
    expect(q.colorMax).toBe(0.25);
    expect(q.colorRange).toBeCloseTo(0.25, 9);
    expect(q.colorInfo.diverging).toBe(true);
    expect(Array.from(q.faceColors.slice(0, 3))).toEqual(QUAD_PAPER.map(Math.fround));
    expect(q.setColorMode('length_error')).toBe(true);
    expect(q.spline.colored).toBe(false);
    expect(q.colorMax).toBeCloseTo(0.01, 6);
    // A geometry without a spline: no control targets, the spline's mode is refused.
    const plain = new QuadMeshBuffers();
    plain.apply(geometry({}, false));
    expect(plain.hasSpline).toBe(false);
    expect(plain.pointTargets().map(targetKey)).toEqual(['v0', 'v1', 'v2', 'v3']);
    expect(plain.setColorMode('spline_gauss')).toBe(false);
    expect(plain.pointOf({ vertex: 0, on: 'control' })).toBe(null);
    q.setColorMode('spline_gauss');
    q.apply(geometry({}, false));
    expect(q.colorMode).toBe('length_error');
    expect(q.spline.surface.drawRange.count).toBe(0);
  });

  it('keeps the spline buffers across iterates', () => {
    const q = new QuadMeshBuffers();
    q.apply(geometry());
    const pos = q.spline.surface.getAttribute('position');
    const moved = CONTROL.map((p, i) => (i === 0 ? [0, 0, 1] : p));
    expect(q.apply(geometry({ control: moved }))).toBe(false);
    expect(q.spline.surface.getAttribute('position')).toBe(pos);
    expect(q.pointOf({ vertex: 0, on: 'control' })).toEqual([0, 0, 1]);
  });
});

describe('control point targets and commands', () => {
  it('address a control point of the net', () => {
    const t = { vertex: 3, on: 'control' };
    expect(targetKey(t)).toBe('m3');
    expect(targetOf({ target: t, position: [0, 0, 0] })).toEqual(t);
    expect(targetOf({ on: 'control', vertex: 3, weight: 1 })).toEqual(t);
    expect(sameTarget(t, { vertex: 3 })).toBe(false);
    expect(sameTarget(t, { vertex: 3, on: 'unfolding' })).toBe(false);
    expect(targetLabel(t)).toBe('control point 3');
  });

  it('drag, release, fix, handle and presence messages are valid for the server', () => {
    const t = { vertex: 7, on: 'control' };
    const msgs = [
      new DragCommand(t, [1, 2, 3]).toMessage(1),
      new DragEndCommand(t).toMessage(2),
      new SetFixedCommand(t, true).toMessage(3),
      new AddHandleCommand(t, [1, 2, 3]).toMessage(4),
      new RemoveHandleCommand(t).toMessage(5),
      new PresenceCommand(t).toMessage(6),
    ];
    for (const m of msgs) expect(validClient(m)).toEqual([]);
    expect(msgs[0]).toEqual({ type: 'drag', op: 1, target: { vertex: 7, on: 'control' }, position: [1, 2, 3] });
    expect(msgs[1]).toEqual({ type: 'drag_end', op: 2, target: { vertex: 7, on: 'control' } });
  });
});

describe('picking prefers control points', () => {
  it('a control point wins over a vertex of M under the pointer', () => {
    const camera = new THREE.PerspectiveCamera(45, 1, 0.1, 100);
    camera.position.set(0, 0, 10);
    camera.lookAt(0, 0, 0);
    camera.updateMatrixWorld();
    const worldPerPixel = (p) => (2 * (camera.position.z - p.z) * Math.tan(THREE.MathUtils.degToRad(22.5))) / 400;
    const sprites = new PointSprites(new THREE.Scene());
    sprites.begin(2);
    // The vertex lies exactly under the pointer, the control point 4 px beside it.
    const wpp = worldPerPixel(new THREE.Vector3());
    sprites.push(new THREE.Vector3(0, 0, 0), 7, 0xffffff, SHAPE_SPHERE, { vertex: 0 });
    sprites.push(new THREE.Vector3(4 * wpp, 0, 0), 7, 0xffffff, SHAPE_SPHERE, { vertex: 0, on: 'control' });
    sprites.end();
    const ray = new THREE.Raycaster();
    ray.setFromCamera(new THREE.Vector2(0, 0), camera);
    expect(sprites.pick(ray, worldPerPixel)).toEqual({ vertex: 0 });
    const q = new QuadMeshBuffers();
    expect(sprites.pick(ray, worldPerPixel, 0, (item) => q.pickPriority(item))).toEqual({ vertex: 0, on: 'control' });
  });
});

describe('spline numbers', () => {
  it('three significant digits', () => {
    expect(significant(0.061807)).toBe('0.0618');
    expect(significant(1.6495)).toBe('1.65');
    expect(significant(3.19e-9)).toBe('3.19e-9');
    expect(significant(0)).toBe('0');
    expect(significant(NaN)).toBe('–');
  });
});
