// Rotating a selected group of a composite's points (issue 16 item 3; rotate_points): the command
// and its checks, the group selection of the editor state, and the pure helpers of the panel.
import { readFileSync } from 'node:fs';
import { fileURLToPath } from 'node:url';
import { describe, expect, it } from 'vitest';
import { RotatePointsCommand } from '../src/commands/index.js';
import { EditorState } from '../src/state/EditorState.js';
import {
  axisVector, centroid, DEFAULT_ROTATE_ANGLE, ROTATE_AXES, rotateCommandFrom, rotatePoint, turnAngle,
} from '../src/geometry/groupRotation.js';
import { makeValidator } from './helpers/jsonschema.js';

const schemaDir = fileURLToPath(new URL('../../proto/schemas/', import.meta.url));
const load = (name) => JSON.parse(readFileSync(schemaDir + name, 'utf8'));
const schemas = { 'ws-client.schema.json': load('ws-client.schema.json'), 'scene.schema.json': load('scene.schema.json') };
const validate = makeValidator(schemas);
const validClient = (msg) => validate(JSON.parse(JSON.stringify(msg)), 'ws-client.schema.json');

const close = (a, b, eps = 1e-12) => a.every((x, k) => Math.abs(x - b[k]) < eps);

describe('RotatePointsCommand', () => {
  it('builds the exact JSON of the protocol', () => {
    expect(new RotatePointsCommand([{ vertex: 2 }, { edge: 4, index: 1 }], [0, 0, 1], 20).toMessage(7)).toEqual({
      type: 'rotate_points', op: 7, targets: [{ vertex: 2 }, { edge: 4, index: 1 }], axis: [0, 0, 1], angle: 20,
    });
    expect(new RotatePointsCommand([{ vertex: 0 }], new Float64Array([1, 0, 0]), -45, { centre: [0, 100, 0], iterations: 0, source: 's' }).toMessage('c-3')).toEqual({
      type: 'rotate_points', op: 'c-3', targets: [{ vertex: 0 }], axis: [1, 0, 0], centre: [0, 100, 0], angle: -45, iterations: 0,
    });
  });

  it('validates against the schema in every variant', () => {
    const variants = [
      new RotatePointsCommand([{ vertex: 0 }], [0, 0, 2], 360),
      new RotatePointsCommand([{ edge: 0, index: 3 }, { vertex: 999999 }], [0.2, -0.4, 0.1], -360, { centre: [1, 2, 3] }),
      new RotatePointsCommand(Array.from({ length: 10000 }, (_, i) => ({ vertex: i })), [1, 1, 1], 0.5, { iterations: 1000 }),
    ];
    for (const c of variants) expect(validClient(c.toMessage(1))).toEqual([]);
  });

  it('the schema rejects what the command refuses', () => {
    const ok = { type: 'rotate_points', op: 1, targets: [{ vertex: 1 }], axis: [0, 0, 1], angle: 10 };
    expect(validClient(ok)).toEqual([]);
    expect(validClient({ ...ok, targets: [] }).length).toBeGreaterThan(0);
    expect(validClient({ ...ok, axis: [0, 1] }).length).toBeGreaterThan(0);
    expect(validClient({ ...ok, angle: 361 }).length).toBeGreaterThan(0);
    expect(validClient({ ...ok, iterations: 1001 }).length).toBeGreaterThan(0);
    expect(validClient({ ...ok, centre: [0, 0] }).length).toBeGreaterThan(0);
    expect(validClient({ ...ok, pivot: [0, 0, 0] }).length).toBeGreaterThan(0);
  });

  it('refuses malformed arguments early, naming the field', () => {
    const t = [{ vertex: 1 }];
    expect(() => new RotatePointsCommand([], [0, 0, 1], 10)).toThrow(/^targets/);
    expect(() => new RotatePointsCommand(null, [0, 0, 1], 10)).toThrow(/^targets/);
    expect(() => new RotatePointsCommand(Array.from({ length: 10001 }, (_, i) => ({ vertex: i })), [0, 0, 1], 10)).toThrow(/^targets/);
    // Composite points only: no strip control points, no quad-mesh unfolding vertices.
    expect(() => new RotatePointsCommand([{ vertex: 1 }, { curve: 'a', index: 0 }], [0, 0, 1], 10)).toThrow(/^targets\[1\]/);
    expect(() => new RotatePointsCommand([{ vertex: 1, on: 'unfolding' }], [0, 0, 1], 10)).toThrow(/^targets\[0\]/);
    expect(() => new RotatePointsCommand([{ vertex: -1 }], [0, 0, 1], 10)).toThrow(/^targets\[0\]/);
    expect(() => new RotatePointsCommand([{ edge: 2 }], [0, 0, 1], 10)).toThrow(/^targets\[0\]/);
    expect(() => new RotatePointsCommand(t, [0, 0, 0], 10)).toThrow(/^axis/);
    expect(() => new RotatePointsCommand(t, [0, 1], 10)).toThrow(/^axis/);
    expect(() => new RotatePointsCommand(t, [0, NaN, 1], 10)).toThrow(/^axis/);
    expect(() => new RotatePointsCommand(t, [0, 0, Infinity], 10)).toThrow(/^axis/);
    expect(() => new RotatePointsCommand(t, [0, 0, 1], 360.5)).toThrow(/^angle/);
    expect(() => new RotatePointsCommand(t, [0, 0, 1], -361)).toThrow(/^angle/);
    expect(() => new RotatePointsCommand(t, [0, 0, 1], NaN)).toThrow(/^angle/);
    expect(() => new RotatePointsCommand(t, [0, 0, 1], '20')).toThrow(/^angle/);
    expect(() => new RotatePointsCommand(t, [0, 0, 1], 10, { centre: [0, 0] })).toThrow(/^centre/);
    expect(() => new RotatePointsCommand(t, [0, 0, 1], 10, { centre: [0, NaN, 0] })).toThrow(/^centre/);
    expect(() => new RotatePointsCommand(t, [0, 0, 1], 10, { iterations: -1 })).toThrow(/^iterations/);
    expect(() => new RotatePointsCommand(t, [0, 0, 1], 10, { iterations: 2.5 })).toThrow(/^iterations/);
    expect(() => new RotatePointsCommand(t, [0, 0, 1], 10, { iterations: 1001 })).toThrow(/^iterations/);
    // The edge control point's addressing is kept; the name says what it does.
    const c = new RotatePointsCommand([{ edge: 0, index: 2 }, { vertex: 3 }], [0, 0, 1], 15);
    expect(c.name).toBe('rotate 2 points by 15°');
    expect(new RotatePointsCommand(t, [0, 0, 1], 15).name).toBe('rotate 1 point by 15°');
  });
});

describe('group selection (EditorState)', () => {
  it('Shift-click toggles points; a single selection joins the group first; the selection follows', () => {
    const s = new EditorState();
    const groups = [];
    s.on('group', (g) => groups.push(g.map((t) => t.vertex ?? `e${t.edge}:${t.index}`)));
    expect(s.rotationTargets()).toEqual([]);
    s.setSelection({ vertex: 2 });
    expect(s.rotationTargets()).toEqual([{ vertex: 2 }]);
    expect(s.toggleGroupMember({ vertex: 3 })).toBe(true);
    expect(s.group).toEqual([{ vertex: 2 }, { vertex: 3 }]);
    expect(s.selection).toEqual({ vertex: 3 });
    expect(s.toggleGroupMember({ edge: 4, index: 1 })).toBe(true);
    expect(s.inGroup({ edge: 4, index: 1 })).toBe(true);
    expect(s.rotationTargets()).toEqual([{ vertex: 2 }, { vertex: 3 }, { edge: 4, index: 1 }]);
    // Removing the last one picked: the selection goes to the last one left.
    expect(s.toggleGroupMember({ edge: 4, index: 1 })).toBe(false);
    expect(s.selection).toEqual({ vertex: 3 });
    expect(s.toggleGroupMember({ vertex: 2 })).toBe(false);
    expect(s.toggleGroupMember({ vertex: 3 })).toBe(false);
    expect(s.group).toEqual([]);
    expect(s.selection).toBe(null);
    expect(groups).toEqual([[2, 3], [2, 3, 'e4:1'], [2, 3], [3], []]);
  });

  it('Shift-clicking the only selected point deselects it', () => {
    const s = new EditorState();
    s.setSelection({ vertex: 5 });
    expect(s.toggleGroupMember({ vertex: 5 })).toBe(false);
    expect(s.group).toEqual([]);
    expect(s.selection).toBe(null);
    expect(s.toggleGroupMember({ vertex: 5 })).toBe(true);
    expect(s.group).toEqual([{ vertex: 5 }]);
  });

  it('a turn (ours or another’s) and a solve make undo available: they send no update', () => {
    const s = new EditorState();
    s.applyUpdate({ type: 'update', seq: 2, undo: { available: 0, redo_available: 1 } });
    s.applyAck({ type: 'ack', op: 1, seq: 3 }, new RotatePointsCommand([{ vertex: 1 }], [0, 0, 1], 20));
    expect(s.undo).toEqual({ available: 1, redo_available: 0 });
    const t = new EditorState();
    t.applyEdit({ type: 'edit', seq: 4, by: 2, edit: { type: 'rotate_points' } });
    expect(t.undo).toEqual({ available: 1, redo_available: 0 });
    const u = new EditorState();
    u.applyEdit({ type: 'edit', seq: 4, by: 2, edit: { type: 'solve' } });
    expect(u.undo).toEqual({ available: 1, redo_available: 0 });
  });

  it('setGroup drops duplicates and signals only changes; the axis has a signal of its own', () => {
    const s = new EditorState();
    let n = 0;
    s.on('group', () => n++);
    expect(s.setGroup([{ vertex: 1 }, { vertex: 1 }, { target: { vertex: 2 } }])).toBe(true);
    expect(s.group).toEqual([{ vertex: 1 }, { vertex: 2 }]);
    expect(s.setGroup([{ vertex: 1 }, { vertex: 2 }])).toBe(false);
    expect(s.setGroup([])).toBe(true);
    expect(s.setGroup(null)).toBe(false);
    expect(n).toBe(2);
    expect(s.rotateAxis).toBe('z');
    const axes = [];
    s.on('rotate-axis', (a) => axes.push(a));
    expect(s.setRotateAxis('view')).toBe(true);
    expect(s.setRotateAxis('view')).toBe(false);
    expect(axes).toEqual(['view']);
    expect(s.rotateCentre).toBe(null);
    expect(s.setRotateCentre([1, 2, 3])).toBe(true);
    expect(s.setRotateCentre([1, 2, 3])).toBe(false);
    expect(s.rotateCentre).toEqual([1, 2, 3]);
    expect(s.setRotateCentre([1, NaN, 3])).toBe(true);
    expect(s.rotateCentre).toBe(null);
    s.setRotateCentre([0, 0, 0]);
    s.reset();
    expect(s.group).toEqual([]);
    expect(s.rotateAxis).toBe('z');
    expect(s.rotateCentre).toBe(null);
  });
});

describe('group rotation helpers', () => {
  it('axis buttons: the coordinate axes and the direction towards the viewer', () => {
    expect(ROTATE_AXES).toEqual(['x', 'y', 'z', 'view']);
    expect(axisVector('x')).toEqual([1, 0, 0]);
    expect(axisVector('z', [1, 2, 3])).toEqual([0, 0, 1]);
    expect(close(axisVector('view', [0, 0, -2]), [0, 0, 1])).toBe(true);
    expect(close(axisVector('view', [3, -4, 0]), [-0.6, 0.8, 0])).toBe(true);
    expect(axisVector('view', [0, 0, 0])).toBe(null);
    expect(axisVector('view', null)).toBe(null);
    expect(axisVector('w')).toBe(null);
  });

  it('centroid of the points there are', () => {
    expect(centroid([[0, 0, 0], [2, 4, 6], null])).toEqual([1, 2, 3]);
    expect(centroid([])).toBe(null);
    expect(centroid([null])).toBe(null);
  });

  it('turns right-handed, as the server does (Eigen AngleAxis), and measures the turn', () => {
    const c = [1, 1, 5];
    const q = rotatePoint([2, 1, 7], c, [0, 0, 3], 90);
    expect(close(q, [1, 2, 7], 1e-12)).toBe(true);
    expect(turnAngle([2, 1, 7], q, c, [0, 0, 1])).toBeCloseTo(90, 10);
    expect(turnAngle([2, 1, 7], q, c, [0, 0, -1])).toBeCloseTo(-90, 10);
    // About x by 60° (the server's test: a flap turned about its crease).
    const p = rotatePoint([0, 150, 0], [0, 100, 0], [1, 0, 0], 60);
    expect(p[1]).toBeCloseTo(125, 10);
    expect(p[2]).toBeCloseTo(50 * Math.sin(Math.PI / 3), 10);
    // An arbitrary axis: the distance to the axis and the component along it stay.
    const axis = [1, -2, 0.5];
    const r = rotatePoint([3, 0, -1], [0.5, 0.5, 0.5], axis, 33);
    expect(turnAngle([3, 0, -1], r, [0.5, 0.5, 0.5], axis)).toBeCloseTo(33, 9);
    expect(Math.hypot(...r.map((x, k) => x - [0.5, 0.5, 0.5][k]))).toBeCloseTo(Math.hypot(2.5, -0.5, -1.5), 12);
    expect(Number.isNaN(turnAngle([0, 0, 1], [0, 0, 2], [0, 0, 0], [0, 0, 1]))).toBe(true);
  });

  it('reads the panel inputs into a command, or says which input is wrong', () => {
    const targets = [{ vertex: 2 }, { vertex: 3 }];
    const base = { targets, axis: 'z', angle: String(DEFAULT_ROTATE_ANGLE), centre: null, iterations: '', source: 'selection:rotate' };
    const { command } = rotateCommandFrom(base);
    expect(command.toMessage(1)).toEqual({ type: 'rotate_points', op: 1, targets, axis: [0, 0, 1], angle: 15 });
    expect(command.source).toBe('selection:rotate');
    expect(rotateCommandFrom({ ...base, angle: '-20', centre: ['1', '2', '0.5'], iterations: '0' }).command.toMessage(2))
      .toEqual({ type: 'rotate_points', op: 2, targets, axis: [0, 0, 1], centre: [1, 2, 0.5], angle: -20, iterations: 0 });
    const view = rotateCommandFrom({ ...base, axis: 'view', viewDirection: [0, 0, -1] }).command;
    expect(close(view.axis, [0, 0, 1])).toBe(true);
    // Blank centre inputs: the server's centroid.
    expect(rotateCommandFrom({ ...base, centre: ['', ' ', ''] }).command.centre).toBeUndefined();
    const field = (input) => rotateCommandFrom({ ...base, ...input }).error.field;
    expect(field({ targets: [] })).toBe('targets');
    expect(field({ angle: '' })).toBe('angle');
    expect(field({ angle: 'abc' })).toBe('angle');
    expect(field({ angle: '400' })).toBe('angle');
    expect(field({ axis: 'view', viewDirection: null })).toBe('axis');
    expect(field({ centre: ['1', '', '2'] })).toBe('centre');
    expect(field({ centre: ['1', 'x', '2'] })).toBe('centre');
    expect(field({ iterations: '2.5' })).toBe('iterations');
    expect(field({ iterations: '-1' })).toBe('iterations');
    expect(field({ iterations: '5000' })).toBe('iterations');
    expect(field({ targets: [{ curve: 'a', index: 0 }] })).toBe('targets[0]');
  });
});
