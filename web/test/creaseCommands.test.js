import { readFileSync } from 'node:fs';
import { fileURLToPath } from 'node:url';
import { describe, expect, it } from 'vitest';
import {
  DRAW_ASSIGNMENTS, DrawCreaseCommand, EraseCreaseCommand, RelabelCreaseCommand, ReshapeCreaseCommand,
} from '../src/commands/index.js';
import { makeValidator } from './helpers/jsonschema.js';

const schemaDir = fileURLToPath(new URL('../../proto/schemas/', import.meta.url));
const load = (name) => JSON.parse(readFileSync(schemaDir + name, 'utf8'));
const schemas = { 'ws-client.schema.json': load('ws-client.schema.json'), 'scene.schema.json': load('scene.schema.json') };
const validate = makeValidator(schemas);
const schemaTypes = new Set(schemas['ws-client.schema.json'].oneOf.map((r) => r.$ref.split('/').pop()));
const drawingInSchema = ['draw_crease', 'erase_crease', 'relabel_crease', 'reshape_crease'].every((t) => schemaTypes.has(t));

const arc = [[0, 75], [50, 90], [100, 97], [150, 90], [200, 75]];

describe('crease drawing commands', () => {
  it('build the exact JSON of the protocol', () => {
    expect(new DrawCreaseCommand([[0, 0], [200, 150]], { curved: false, assignment: 'M', foldAngle: 45 }).toMessage(3))
      .toEqual({ type: 'draw_crease', op: 3, points: [[0, 0], [200, 150]], curved: false, assignment: 'M', fold_angle: 45 });
    expect(new DrawCreaseCommand(arc, { curved: true }).toMessage(4))
      .toEqual({ type: 'draw_crease', op: 4, points: arc, curved: true, assignment: 'V' });
    // Flat and cut creases do not fold: no angle.
    expect(new DrawCreaseCommand([[0, 0], [1, 1]], { assignment: 'F', foldAngle: 90 }).toMessage(5))
      .toEqual({ type: 'draw_crease', op: 5, points: [[0, 0], [1, 1]], curved: false, assignment: 'F' });
    expect(new EraseCreaseCommand(4).toMessage('c-1')).toEqual({ type: 'erase_crease', op: 'c-1', crease: 4 });
    expect(new RelabelCreaseCommand(2, 'M', 90).toMessage(6)).toEqual({ type: 'relabel_crease', op: 6, crease: 2, assignment: 'M', fold_angle: 90 });
    expect(new RelabelCreaseCommand(2, 'C', 90).toMessage(7)).toEqual({ type: 'relabel_crease', op: 7, crease: 2, assignment: 'C' });
    expect(new RelabelCreaseCommand(2, 'V').toMessage()).toEqual({ type: 'relabel_crease', crease: 2, assignment: 'V' });
    expect(new ReshapeCreaseCommand(1, arc, true).toMessage(8)).toEqual({ type: 'reshape_crease', op: 8, crease: 1, points: arc, curved: true });
    expect(new ReshapeCreaseCommand(1, [[0, 0], [3, 4]]).toMessage(9)).toEqual({ type: 'reshape_crease', op: 9, crease: 1, points: [[0, 0], [3, 4]] });
  });

  it('copy points as plain numbers (typed arrays, strings of numbers)', () => {
    const c = new DrawCreaseCommand([new Float64Array([1, 2]), ['3', '4']]);
    expect(c.toMessage(1).points).toEqual([[1, 2], [3, 4]]);
    expect(Array.isArray(c.points[0])).toBe(true);
  });

  it('refuse malformed arguments before sending, naming the field', () => {
    expect(() => new DrawCreaseCommand([[0, 0]])).toThrow(/points/);
    expect(() => new DrawCreaseCommand(Array.from({ length: 201 }, (_, i) => [i, 0]), { curved: true })).toThrow(/points/);
    expect(() => new DrawCreaseCommand([[0, 0], [1, NaN]])).toThrow(/points\[1\]/);
    expect(() => new DrawCreaseCommand([[0, 0], [1, 1, 1]])).toThrow(/points\[1\]/);
    expect(() => new DrawCreaseCommand([[0, 0], [1, Infinity]])).toThrow(/finite/);
    expect(() => new DrawCreaseCommand([[0, 0], [1, 1], [2, 0]], { curved: false })).toThrow(/straight crease has exactly 2/);
    expect(() => new DrawCreaseCommand([[0, 0], [1, 1]], { curved: true })).toThrow(/at least 3/);
    expect(() => new DrawCreaseCommand([[0, 0], [1, 1]], { curved: 'yes' })).toThrow(/curved/);
    expect(() => new DrawCreaseCommand([[0, 0], [1, 1]], { assignment: 'B' })).toThrow(/assignment/);
    expect(() => new DrawCreaseCommand([[0, 0], [1, 1]], { assignment: 'X' })).toThrow(/assignment/);
    for (const bad of [0, -10, 181, NaN, '90']) {
      expect(() => new DrawCreaseCommand([[0, 0], [1, 1]], { assignment: 'V', foldAngle: bad })).toThrow(/fold_angle/);
      expect(() => new RelabelCreaseCommand(0, 'M', bad)).toThrow(/fold_angle/);
    }
    expect(new DrawCreaseCommand([[0, 0], [1, 1]], { assignment: 'V', foldAngle: 180 }).foldAngle).toBe(180);
    for (const bad of [-1, 1.5, '2', null, 100000]) {
      expect(() => new EraseCreaseCommand(bad)).toThrow(/crease/);
      expect(() => new RelabelCreaseCommand(bad, 'M')).toThrow(/crease/);
      expect(() => new ReshapeCreaseCommand(bad, [[0, 0], [1, 1]])).toThrow(/crease/);
    }
    expect(() => new RelabelCreaseCommand(0, 'B')).toThrow(/assignment/);
    expect(() => new ReshapeCreaseCommand(0, [[0, 0]])).toThrow(/points/);
    expect(() => new ReshapeCreaseCommand(0, [[0, 0], [1, 1], [2, 2]], false)).toThrow(/exactly 2/);
    expect(() => new ReshapeCreaseCommand(0, [[0, 0], [1, 1]], true)).toThrow(/at least 3/);
    expect(DRAW_ASSIGNMENTS).toEqual(['M', 'V', 'F', 'C']);
  });

  it('carry a name for error toasts and a source for error slots', () => {
    const c = new DrawCreaseCommand(arc, { curved: true, assignment: 'V' }, { source: 'crease-board:draw' });
    expect(c.name).toBe('draw a curved valley crease');
    expect(c.source).toBe('crease-board:draw');
    expect(new RelabelCreaseCommand(3, 'M', 60).name).toBe('crease 3 → mountain 60°');
  });

  it.skipIf(!drawingInSchema)('match ws-client.schema.json', () => {
    const msgs = [
      new DrawCreaseCommand([[0, 0], [200, 150]], { assignment: 'M', foldAngle: 45 }),
      new DrawCreaseCommand(arc, { curved: true, assignment: 'C' }),
      new EraseCreaseCommand(0),
      new RelabelCreaseCommand(1, 'F'),
      new RelabelCreaseCommand(1, 'V', 180),
      new ReshapeCreaseCommand(2, arc, true),
      new ReshapeCreaseCommand(2, [[0, 0], [1, 1]]),
    ];
    for (const c of msgs) {
      for (const op of [1, 'c-17', undefined]) expect(validate(JSON.parse(JSON.stringify(c.toMessage(op))), 'ws-client.schema.json')).toEqual([]);
    }
  });
});
