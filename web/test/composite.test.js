import { describe, expect, it } from 'vitest';
import { encodeArray } from '../src/geometry/decode.js';
import { CompositeBuffers, edgeLineSet, targetOfRef } from '../src/geometry/CompositeBuffers.js';
import { sameTarget, targetKey, targetLabel, targetOf } from '../src/commands/Command.js';
import { EditorState } from '../src/state/EditorState.js';

const f32 = (rows, shape) => encodeArray(Float32Array.from(rows.flat()), shape);
const i32 = (rows, shape) => encodeArray(Int32Array.from(rows.flat()), shape);

/** A unit square split into two faces by a crease from (0.5,0,0) to (0.5,1,0) lifted at x = 1. */
function squareGeometry({ lift = 0.2, flatness = [1e-4, 3e-3], assignment = 'V', development = true } = {}) {
  const vertices = [[0, 0, 0], [0.5, 0, 0], [0.5, 1, 0], [0, 1, 0], [0.5, 0, 0], [1, 0, lift], [1, 1, lift], [0.5, 1, 0]];
  return {
    kind: 'composite',
    surface: {
      vertices: f32(vertices, [8, 3]),
      quads: i32([[0, 1, 2, 3], [4, 5, 6, 7]], [2, 4]),
      quad_face: i32([[0], [1]], [2, 1]),
      face_flatness: f32([[flatness[0]], [flatness[0]], [flatness[0]], [flatness[0]], [flatness[1]], [flatness[1]], [flatness[1]], [flatness[1]]], [8, 1]),
      vertex_curvature: f32(vertices.map(() => [0]), [8, 1]),
    },
    vertices: f32([[0, 0, 0], [0.5, 0, 0], [1, 0, lift], [1, 1, lift], [0.5, 1, 0], [0, 1, 0]], [6, 3]),
    vertex_curvature: f32([[0], [0], [0], [0], [0], [0]], [6, 1]),
    face_flatness: f32([[flatness[0]], [flatness[1]]], [2, 1]),
    edges: [
      { edge: 0, v: [1, 4], type: 'S', crease: 'fold', interior: true, assignment,
        polyline: f32([[0.5, 0, 0], [0.5, 0.5, 0], [0.5, 1, 0]], [3, 3]), fold_angle_deg: f32([[20], [22], [24]], [3, 1]),
        control_points: f32([[0.5, 0, 0], [0.55, 0.5, 0], [0.5, 1, 0]], [3, 3]) },
      { edge: 1, v: [0, 1], type: 'R', crease: 'none', interior: false, assignment: 'B', polyline: f32([[0, 0, 0], [0.5, 0, 0]], [2, 3]) },
    ],
    points: {
      positions: f32([[0, 0, 0], [0.5, 0, 0], [1, 0, lift], [1, 1, lift], [0.5, 1, 0], [0, 1, 0], [0.55, 0.5, 0]], [7, 3]),
      refs: i32([[0, -1, -1], [1, -1, -1], [2, -1, -1], [3, -1, -1], [4, -1, -1], [5, -1, -1], [-1, 0, 1]], [7, 3]),
    },
    development: development ? {
      vertices: f32([[0, 0], [0.5, 0], [1, 0], [1, 1], [0.5, 1], [0, 1]], [6, 2]),
      triangles: i32([[0, 1, 4], [0, 4, 5], [1, 2, 3], [1, 3, 4]], [4, 3]),
      triangle_face: i32([[0], [0], [1], [1]], [4, 1]),
      edges: i32([[0, 1], [1, 4], [1, 2]], [3, 2]),
      assignment: 'BVB',
      rulings: f32([[0.25, 0, 0.25, 1]], [1, 4]),
    } : null,
  };
}

describe('composite point targets', () => {
  it('key, compare and label vertices, S-edge control points and strip points', () => {
    expect(targetKey({ vertex: 3 })).toBe('v3');
    expect(targetKey({ edge: 0, index: 2 })).toBe('e0:2');
    expect(targetKey({ curve: 'a', index: 2 })).toBe('a2');
    expect(sameTarget({ vertex: 3 }, { target: { vertex: 3 }, position: [0, 0, 0] })).toBe(true);
    expect(sameTarget({ vertex: 3, position: [1, 1, 1] }, { vertex: 3 })).toBe(true);
    expect(sameTarget({ edge: 0, index: 2 }, { edge: 0, index: 1 })).toBe(false);
    expect(sameTarget(null, null)).toBe(false);
    expect(targetOf({ edge: 1, index: 2, weight: 1 })).toEqual({ edge: 1, index: 2 });
    expect(targetLabel({ vertex: 4 })).toBe('vertex 4');
    expect(targetLabel({ edge: 1, index: 2 })).toBe('edge 1 [2]');
    expect(targetOfRef(Int32Array.from([-1, 3, 2, 5, -1, -1]), 0)).toEqual({ edge: 3, index: 2 });
    expect(targetOfRef(Int32Array.from([-1, 3, 2, 5, -1, -1]), 1)).toEqual({ vertex: 5 });
  });

  it('the editor state selects composite points and edges', () => {
    const s = new EditorState();
    const seen = [];
    s.on('edge-selection', (e) => seen.push(e));
    expect(s.setSelection({ vertex: 2 })).toBe(true);
    expect(s.setSelection({ vertex: 2 })).toBe(false);
    expect(s.selection).toEqual({ vertex: 2 });
    expect(s.setSelectedEdge(3)).toBe(true);
    expect(s.setSelectedEdge(3)).toBe(false);
    s.setSelectedEdge(null);
    expect(seen).toEqual([3, null]);
    s.applyState({ session: 's', role: 'edit', you: 1, seq: 0, scene: { model: { kind: 'composite' } } });
    expect(s.kind).toBe('composite');
  });
});

describe('CompositeBuffers', () => {
  it('decodes faces, colour fields, edges by assignment, points and the development', () => {
    const b = new CompositeBuffers();
    b.apply(squareGeometry());
    expect(b.hasData).toBe(true);
    expect(b.surface.getAttribute('position').count).toBe(8);
    expect(b.surface.index.count).toBe(12);
    expect(b.surface.getAttribute('color').count).toBe(8);
    // flatness colouring: the scale covers the largest δ with a nice number
    expect(b.colorMax).toBeCloseTo(3e-3, 6);
    expect(b.colorRange).toBeGreaterThanOrEqual(3e-3);
    // the crease is a valley: two segments of its 3-sample polyline
    expect(b.lines.valley.drawRange.count).toBe(4);
    expect(b.lines.mountain.drawRange.count).toBe(0);
    expect(b.lines.boundary.drawRange.count).toBe(2);
    expect(b.lines.polygons.drawRange.count).toBe(4);
    expect(b.edge(0).foldAngleDeg).toBeCloseTo(22, 5);
    expect(b.edge(0).midpoint).toEqual([0.5, 0.5, 0]);
    expect(b.pointTargets()).toHaveLength(7);
    expect(b.pointOf({ vertex: 2 })[2]).toBeCloseTo(0.2, 6);
    expect(b.pointOf({ edge: 0, index: 1 })[0]).toBeCloseTo(0.55, 6);
    expect(b.pointOf({ edge: 9, index: 1 })).toBeNull();
    expect(b.development.count).toBe(6);
    expect(b.development.assignment).toBe('BVB');
    expect(b.development.triangles).toHaveLength(12);
  });

  it('switches the colour field and keeps buffers when sizes stay', () => {
    const b = new CompositeBuffers();
    b.apply(squareGeometry());
    const positions = b.surface.getAttribute('position');
    expect(b.setColorMode('curvature')).toBe(true);
    expect(b.colorInfo.title).toBe('vertex curvature');
    expect(b.colorMax).toBe(0);
    expect(b.setColorMode('curvature')).toBe(false);
    expect(b.setColorMode('nonsense')).toBe(false);
    b.apply(squareGeometry({ lift: 0.4, assignment: 'M', development: false }));
    expect(b.surface.getAttribute('position')).toBe(positions);
    expect(b.pointOf({ vertex: 3 })[2]).toBeCloseTo(0.4, 6);
    expect(b.lines.mountain.drawRange.count).toBe(4);
    expect(b.lines.valley.drawRange.count).toBe(0);
    expect(b.development).toBeNull();
  });

  it('sorts edges into line sets by assignment', () => {
    expect(edgeLineSet({ interior: false, assignment: 'B' })).toBe('boundary');
    expect(edgeLineSet({ interior: true, assignment: 'M' })).toBe('mountain');
    expect(edgeLineSet({ interior: true, assignment: 'V' })).toBe('valley');
    expect(edgeLineSet({ interior: true, assignment: 'F' })).toBe('flat');
  });

  it('rejects strip geometry', () => {
    expect(() => new CompositeBuffers().apply({ kind: 'strip' })).toThrow(/unsupported/);
  });
});

describe('fold slider position', () => {
  it('follows the metrics while folding, then the scene, else the design (100 %)', async () => {
    const { sessionFoldAmount } = await import('../src/ui/FoldPanel.js');
    expect(sessionFoldAmount({ fold_amount: 0.4 }, { model: { fold_amount: 0.2 } })).toBe(0.4);
    expect(sessionFoldAmount({}, { model: { fold_amount: 0.2 } })).toBe(0.2);
    expect(sessionFoldAmount(null, { model: {} })).toBe(1);
  });
});

describe('fold lag warning', () => {
  const scene = { model: { fold_angles: [{ edge: 0, angle: 90 }, { edge: 4, angle: -90 }, { edge: 8, angle: 45 }] } };
  it('says a crease folds the wrong way when it is further from its target than the target itself', async () => {
    const { foldLagWarning } = await import('../src/ui/FoldPanel.js');
    // A new user's drawing let go at 100 %: a valley folded as a mountain, 97° from its 90°.
    const text = foldLagWarning({ fold_amount: 1, fold_angle_error_max_deg: 97.2 }, scene);
    expect(text).toMatch(/97° from its target at 100 %: it folds the wrong way/);
    expect(foldLagWarning({ fold_amount: 0.5, fold_angle_error_max_deg: 30 }, scene)).toMatch(/lag behind the slider/);
  });
  it('names the drawing as the thing to change only when the design has one', async () => {
    const { foldLagWarning } = await import('../src/ui/FoldPanel.js');
    // A preset (no drawing) whose crease a co-designer made smooth: there was "no drawing" to change.
    expect(foldLagWarning({ fold_amount: 1, fold_angle_error_max_deg: 60 }, scene)).toMatch(/change the creases \(their types/);
    const drawn = { model: { ...scene.model, drawing: { strokes: [] } } };
    expect(foldLagWarning({ fold_amount: 1, fold_angle_error_max_deg: 60 }, drawn)).toMatch(/change the drawing/);
  });
  it('stays quiet for folds near their targets, at 0 %, without targets or without the metric', async () => {
    const { foldLagWarning } = await import('../src/ui/FoldPanel.js');
    expect(foldLagWarning({ fold_amount: 1, fold_angle_error_max_deg: 13.5 }, scene)).toBeNull();  // within a quarter of 90°
    expect(foldLagWarning({ fold_amount: 0.1, fold_angle_error_max_deg: 4.9 }, scene)).toBeNull();  // under 5°
    expect(foldLagWarning({ fold_amount: 0, fold_angle_error_max_deg: 40 }, scene)).toBeNull();
    expect(foldLagWarning({ fold_amount: 1, fold_angle_error_max_deg: 40 }, { model: {} })).toBeNull();
    expect(foldLagWarning({ fold_amount: 1 }, scene)).toBeNull();
  });
});
