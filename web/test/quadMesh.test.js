import { describe, expect, it } from 'vitest';
import {
  QUAD_BOUNDARY_EDGE, QUAD_EDGE, QUAD_PAPER, QuadMeshBuffers, boundaryVertexFlags, isQuadMeshGeometry, maxAbs, triangulateFaces,
} from '../src/geometry/QuadMeshBuffers.js';
import { divergingColorAt } from '../src/geometry/colormap.js';
import {
  AddHandleCommand, DragCommand, DragEndCommand, RemoveHandleCommand, SetFixedCommand, SetParamsCommand, sameTarget, targetKey, targetLabel, targetOf,
} from '../src/commands/index.js';
import { glueCommand, gluePairList, isGlued, normalizedGlue, withGluePair, withoutGluePair } from '../src/commands/glue.js';
import { percent } from '../src/ui/QuadMeshControls.js';
import { exportFormats } from '../src/ui/exportFormats.js';
import { f32, i32, validClient } from './helpers/proto.js';


/**
 * Two unit quads and a triangle on the right, lifted at x = 2; M′ flat. Vertices:
 *   3 — 4 — 5
 *   |   |   | \
 *   0 — 1 — 2 — 6
 */
function sheet({ curvature = false, glue = [[0, 6]] } = {}) {
  const mesh = [[0, 0, 0], [1, 0, 0], [2, 0, 0.5], [0, 1, 0], [1, 1, 0], [2, 1, 0.5], [3, 0, 0.5]];
  const unfolding = [[0, 0, 0], [1, 0, 0], [2, 0, 0], [0, 1, 0], [1, 1, 0], [2, 1, 0], [3, 0, 0]];
  const edges = [[0, 1], [1, 2], [2, 6], [3, 4], [4, 5], [0, 3], [1, 4], [2, 5], [5, 6]];
  const boundary = [[1], [1], [1], [1], [1], [1], [0], [0], [1]];
  return {
    kind: 'quad_mesh',
    mesh: f32(mesh, [7, 3]),
    unfolding: f32(unfolding, [7, 3]),
    faces: i32([[0, 1, 4, 3], [1, 2, 5, 4], [2, 6, 5, -1]], [3, 4]),
    edges: i32(edges, [9, 2]),
    edge_boundary: i32(boundary, [9, 1]),
    edge_length_error: f32([[0], [0.02], [-0.04], [0], [0.01], [0], [0], [0.005], [0]], [9, 1]),
    face_area_error: f32([[0], [0.01], [0.02]], [3, 1]),
    glue: i32(glue, [glue.length, 2]),
    glue_unfolding: i32([], [0, 2]),
    variable: 'both',
    planar: true,
    conformal: false,
    curvature: curvature ? {
      gauss: f32([[0], [-0.5], [0.25]], [3, 1]),
      mean: f32([[0.1], [0.2], [0.3]], [3, 1]),
      kappa1: f32([[0.2], [0.4], [0.6]], [3, 1]),
      kappa2: f32([[0], [0], [0]], [3, 1]),
      // Face 2's ruling has zero length (not developable there): not drawn.
      rulings: f32([[0.5, 0, 0, 0.5, 1, 0], [1.5, 0, 0.25, 1.5, 1, 0.25], [2.3, 0.3, 0.5, 2.3, 0.3, 0.5]], [3, 6]),
    } : null,
  };
}

describe('quad_mesh geometry', () => {
  it('is recognised by kind, or by its fields when kind is absent', () => {
    expect(isQuadMeshGeometry(sheet())).toBe(true);
    const { kind, ...noKind } = sheet();
    expect(kind).toBe('quad_mesh');
    expect(isQuadMeshGeometry(noKind)).toBe(true);
    expect(isQuadMeshGeometry({ kind: 'composite', mesh: {}, unfolding: {}, faces: {}, edges: {} })).toBe(false);
    expect(isQuadMeshGeometry({ kind: 'strip' })).toBe(false);
    expect(isQuadMeshGeometry(null)).toBe(false);
  });

  it('splits quads into two triangles and keeps triangles whole', () => {
    const { triangles, triFace } = triangulateFaces(Int32Array.from([0, 1, 4, 3, 2, 6, 5, -1]));
    expect(Array.from(triangles)).toEqual([0, 1, 4, 0, 4, 3, 2, 6, 5]);
    expect(Array.from(triFace)).toEqual([0, 0, 1]);
  });

  it('marks the end points of boundary edges', () => {
    const flags = boundaryVertexFlags(Int32Array.from([0, 1, 1, 2, 2, 3]), Int32Array.from([1, 0, 0]), 4);
    expect(Array.from(flags)).toEqual([1, 1, 0, 0]);
    expect(maxAbs(Float32Array.from([0.1, -0.3, NaN, 0.2]))).toBeCloseTo(0.3, 7);
  });

  it('fills M as flat-shaded triangles, edges, glue links; addresses vertices of M and M′', () => {
    const q = new QuadMeshBuffers();
    q.apply(sheet());
    expect(q.vertexCount).toBe(7);
    expect(q.faceCount).toBe(3);
    expect(q.edgeCount).toBe(9);
    expect(q.surface.drawRange.count).toBe(15);  // 2 + 2 + 1 triangles
    const pos = q.surface.getAttribute('position').array;
    expect(Array.from(pos.slice(9, 12))).toEqual([0, 0, 0]);  // triangle 1 = (0, 4, 3) starts at vertex 0
    expect(Array.from(pos.slice(12, 15))).toEqual([1, 1, 0]);
    expect(q.surface.getAttribute('normal').array[2]).toBeCloseTo(1, 6);  // face 0 lies in z = 0
    expect(q.edgeLines.drawRange.count).toBe(18);
    expect(q.glueLines.drawRange.count).toBe(2);
    expect(Array.from(q.glueLines.getAttribute('position').array.slice(0, 6))).toEqual([0, 0, 0, 3, 0, 0.5]);
    expect(Array.from(q.boundary)).toEqual([1, 1, 1, 1, 1, 1, 1]);
    expect(q.glued[0]).toBe(1);
    expect(q.glued[6]).toBe(1);
    expect(q.glued[4]).toBe(0);
    expect(q.pointTargets()).toHaveLength(7);
    expect(q.pointOf({ vertex: 2 })).toEqual([2, 0, 0.5]);
    expect(q.pointOf({ vertex: 2, on: 'unfolding' })).toEqual([2, 0, 0]);
    expect(q.pointOf({ vertex: 7 })).toBe(null);
    expect(q.unfoldingVariable).toBe(true);
    expect(q.meshVariable).toBe(true);
    expect(q.hasCurvature).toBe(false);
    expect(q.rulings.drawRange.count).toBe(0);
  });

  it('colours edges by |l′ − l|/l and faces plain in L-Err mode; K and H per face on a diverging map', () => {
    const q = new QuadMeshBuffers();
    q.apply(sheet({ curvature: true }));
    expect(q.colorMode).toBe('length_error');
    expect(q.colorMax).toBeCloseTo(0.04, 7);
    expect(q.colorRange).toBeCloseTo(0.05, 9);
    expect(Array.from(q.faceColors.slice(0, 3))).toEqual(QUAD_PAPER.map(Math.fround));
    // Edge 2 has |error| 0.04 of a 0.05 scale: between the yellow and red stops.
    const e2 = q.edgeColors.slice(6, 9);
    expect(e2[0]).toBeGreaterThan(0.85);
    expect(e2[2]).toBeLessThan(0.2);
    // Edges 1 and 2: +0.02 and −0.04 — the magnitude counts.
    expect(q.edgeColors[3 * 2]).toBeGreaterThan(q.edgeColors[3 * 1]);

    expect(q.setColorMode('gauss')).toBe(true);
    expect(q.setColorMode('gauss')).toBe(false);
    expect(q.setColorMode('bogus')).toBe(false);
    expect(q.colorMax).toBeCloseTo(0.5, 7);
    expect(q.colorRange).toBeCloseTo(0.5, 9);
    const expected = divergingColorAt(-1, [0, 0, 0]);
    expect(Array.from(q.faceColors.slice(3, 6))).toEqual(expected.map(Math.fround));  // K = −0.5 → the blue end
    expect(Array.from(q.faceColors.slice(0, 3))).toEqual(divergingColorAt(0, [0, 0, 0]).map(Math.fround));
    expect(q.faceColors[6]).toBeGreaterThan(q.faceColors[8]);  // K > 0 is red
    expect(Array.from(q.edgeColors.slice(0, 3))).toEqual(QUAD_BOUNDARY_EDGE.map(Math.fround));
    expect(Array.from(q.edgeColors.slice(18, 21))).toEqual(QUAD_EDGE.map(Math.fround));  // edge 6 is interior
    // The 3D surface carries the same colours (linear) on every vertex of the face's triangles.
    const c = q.surface.getAttribute('color').array;
    expect(c[9 * 2]).toBeCloseTo(c[9 * 3], 7);  // triangles 2 and 3 both belong to face 1

    expect(q.setColorMode('mean')).toBe(true);
    expect(q.colorMax).toBeCloseTo(0.3, 6);
    // Rulings: faces 0 and 1 (face 2's segment has zero length).
    expect(q.rulingCount).toBe(2);
    expect(q.rulings.drawRange.count).toBe(4);
  });

  it('draws faces plain while K waits for the Gauss image', () => {
    const q = new QuadMeshBuffers();
    q.setColorMode('gauss');
    q.apply(sheet());
    expect(q.colorValues()).toBe(null);
    expect(Array.from(q.faceColors.slice(0, 3))).toEqual(QUAD_PAPER.map(Math.fround));
    q.apply(sheet({ curvature: true }));
    expect(q.colorMax).toBeCloseTo(0.5, 7);
  });

  it('keeps its buffers when the next geometry has the same sizes', () => {
    const q = new QuadMeshBuffers();
    q.apply(sheet());
    const attr = q.surface.getAttribute('position');
    expect(q.apply(sheet())).toBe(false);
    expect(q.surface.getAttribute('position')).toBe(attr);
    expect(q.version).toBe(2);
    expect(q.apply(sheet({ glue: [[0, 6], [3, 5]] }))).toBe(true);  // the glue links grew
  });

  it('refuses an unfolding of another size', () => {
    const g = sheet();
    g.unfolding = f32([[0, 0, 0]], [1, 3]);
    expect(() => new QuadMeshBuffers().apply(g)).toThrow(/unfolding/);
  });
});

describe('quad_mesh targets and commands', () => {
  it('address a vertex of M or of M′', () => {
    expect(targetKey({ vertex: 3 })).toBe('v3');
    expect(targetKey({ vertex: 3, on: 'unfolding' })).toBe('u3');
    expect(targetKey({ vertex: 3, on: 'mesh' })).toBe('v3');
    expect(sameTarget({ vertex: 3, on: 'unfolding' }, { target: { on: 'unfolding', vertex: 3 }, position: [0, 0, 0] })).toBe(true);
    expect(sameTarget({ vertex: 3, on: 'unfolding' }, { vertex: 3 })).toBe(false);
    expect(targetOf({ vertex: 2, on: 'mesh', weight: 1 })).toEqual({ vertex: 2 });
    expect(targetLabel({ vertex: 4, on: 'unfolding' })).toBe('vertex 4 of M′');
  });

  it('drag, release, fix and handle M′ vertices with valid messages', () => {
    const u = { vertex: 5, on: 'unfolding' };
    const msgs = [
      new DragCommand(u, [1, 2, 0]).toMessage(1),
      new DragEndCommand(u).toMessage(2),
      new SetFixedCommand(u, true).toMessage(3),
      new AddHandleCommand(u, [1, 2, 0]).toMessage(4),
      new RemoveHandleCommand(u).toMessage(5),
      new DragCommand({ vertex: 5, on: 'mesh' }, [1, 2, 3]).toMessage(6),
    ];
    for (const m of msgs) expect(validClient(m)).toEqual([]);
    expect(msgs[0]).toEqual({ type: 'drag', op: 1, target: { vertex: 5, on: 'unfolding' }, position: [1, 2, 0] });
    expect(msgs[5].target).toEqual({ vertex: 5 });
    expect(() => new DragCommand({ vertex: 5, on: 'paper' }, [0, 0, 0])).toThrow(/invalid point target/);
  });

  it('set_params of a quad mesh: the Gauss image, weights, glue — checked, and valid for the server', () => {
    const gauss = new SetParamsCommand('quad_mesh', { gauss_image: true }).toMessage(1);
    expect(gauss).toEqual({ type: 'set_params', op: 1, params: { gauss_image: true } });
    const all = new SetParamsCommand('quad_mesh', {
      gauss_image: false, conformal: true, variable: 'both', weights: { isometry: 2 }, schedule: { rounds: 4 },
      glue: [{ on: 'mesh', pairs: [[1, 2]] }, { pairs: [[3, 4]] }],
    }).toMessage(2);
    expect(all.params.glue[1]).toEqual({ on: 'mesh', pairs: [[3, 4]] });
    for (const m of [gauss, all]) expect(validClient(m)).toEqual([]);
    expect(() => new SetParamsCommand('quad_mesh', { gauss_image: 1 })).toThrow(/params\.gauss_image/);
    expect(() => new SetParamsCommand('quad_mesh', { variable: 'neither' })).toThrow(/params\.variable/);
    expect(() => new SetParamsCommand('quad_mesh', { weights: { isometry: -1 } })).toThrow(/params\.weights\.isometry/);
    expect(() => new SetParamsCommand('quad_mesh', { glue: [{ on: 'mesh', pairs: [[1, 1]] }] })).toThrow(/params\.glue\[0\]\.pairs\[0\]/);
    expect(() => new SetParamsCommand('quad_mesh', { glue: [{ on: 'sky', pairs: [] }] })).toThrow(/params\.glue\[0\]\.on/);
    expect(() => new SetParamsCommand('quad_mesh', { np: 3 })).toThrow(/params\.np/);
  });
});

describe('glue list edits', () => {
  const glue = [{ on: 'mesh', pairs: [[1, 2], [3, 4]] }, { on: 'unfolding', pairs: [[5, 6]] }];

  it('append a pair to the last group of its side, or a new group', () => {
    expect(withGluePair(glue, 'mesh', 7, 8)).toEqual([{ on: 'mesh', pairs: [[1, 2], [3, 4], [7, 8]] }, { on: 'unfolding', pairs: [[5, 6]] }]);
    expect(withGluePair(undefined, 'unfolding', 0, 9)).toEqual([{ on: 'unfolding', pairs: [[0, 9]] }]);
    expect(withGluePair([{ pairs: [[1, 2]] }], 'mesh', 2, 3)).toEqual([{ on: 'mesh', pairs: [[1, 2], [2, 3]] }]);
    expect(glue[0].pairs).toHaveLength(2);  // the scene's list is not touched
  });

  it('refuse a vertex glued to itself and a pair glued already (either order)', () => {
    expect(() => withGluePair(glue, 'mesh', 4, 4)).toThrow(/itself/);
    expect(() => withGluePair(glue, 'mesh', 4, 3)).toThrow(/already glued/);
    expect(isGlued(glue, 'unfolding', 6, 5)).toBe(true);
    expect(isGlued(glue, 'mesh', 5, 6)).toBe(false);
    expect(() => withGluePair(glue, 'paper', 1, 9)).toThrow(/mesh or unfolding/);
  });

  it('remove a pair by its place; an emptied group goes', () => {
    expect(withoutGluePair(glue, 0, 0)).toEqual([{ on: 'mesh', pairs: [[3, 4]] }, { on: 'unfolding', pairs: [[5, 6]] }]);
    expect(withoutGluePair(glue, 1, 0)).toEqual([{ on: 'mesh', pairs: [[1, 2], [3, 4]] }]);
    expect(() => withoutGluePair(glue, 1, 1)).toThrow(RangeError);
  });

  it('read the scene\'s spelling: bare pairs of M form one group where the first stands', () => {
    const scene = [[1, 2], { on: 'unfolding', pairs: [[5, 6]] }, [3, 4]];
    expect(normalizedGlue(scene)).toEqual([{ on: 'mesh', pairs: [[1, 2], [3, 4]] }, { on: 'unfolding', pairs: [[5, 6]] }]);
    expect(withGluePair(scene, 'mesh', 7, 8)).toEqual([{ on: 'mesh', pairs: [[1, 2], [3, 4], [7, 8]] }, { on: 'unfolding', pairs: [[5, 6]] }]);
    expect(isGlued(scene, 'mesh', 4, 3)).toBe(true);
    expect(gluePairList(scene).map((p) => `${p.on}:${p.pair.join('-')}@${p.group}.${p.index}`)).toEqual(['mesh:1-2@0.0', 'mesh:3-4@0.1', 'unfolding:5-6@1.0']);
    expect(withoutGluePair(scene, 0, 1)).toEqual([{ on: 'mesh', pairs: [[1, 2]] }, { on: 'unfolding', pairs: [[5, 6]] }]);
  });

  it('list the pairs in order and send the whole list', () => {
    expect(gluePairList(glue).map((p) => `${p.on}:${p.pair.join('-')}@${p.group}.${p.index}`)).toEqual(['mesh:1-2@0.0', 'mesh:3-4@0.1', 'unfolding:5-6@1.0']);
    const msg = glueCommand(withGluePair(glue, 'mesh', 7, 8)).toMessage(3);
    expect(msg.params.glue[0].pairs).toEqual([[1, 2], [3, 4], [7, 8]]);
    expect(validClient(msg)).toEqual([]);
  });
});

describe('metric formats', () => {
  it('percent with three digits as in Fig. 22', () => {
    expect(percent(0.00093)).toBe('0.093 %');
    expect(percent(0.0055060376)).toBe('0.551 %');
    expect(percent(0)).toBe('0 %');
    expect(percent(1e-9)).toBe('1.00e-7 %');
    expect(percent(undefined)).toBe('–');
  });
});

describe('export menu of a quad_mesh scene', () => {
  it('offers the flat pattern unless the scene says its unfolding is a second surface', () => {
    const flat = exportFormats('quad_mesh', { kind: 'quad_mesh', mesh: { vertices: [], faces: [] }, unfolding: { vertices: [] } });
    expect(flat).toEqual(expect.arrayContaining(['svg', 'dxf', 'fold']));
    const surface = exportFormats('quad_mesh', { kind: 'quad_mesh', mesh: { vertices: [], faces: [] }, unfolding: { planar: false } });
    expect(surface).not.toContain('svg');
    expect(surface).not.toContain('dxf');
  });
});
