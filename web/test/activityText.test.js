import { readFileSync } from 'node:fs';
import { fileURLToPath } from 'node:url';
import { describe, expect, it } from 'vitest';
import { UNLISTED_MESSAGES, describeEdit } from '../src/ui/activityText.js';
import { validClient } from './helpers/proto.js';

// Every client message type of proto/schemas/ws-client.schema.json (discovered: a new edit gets
// no line of the activity list until it has words and an example here).
const schema = JSON.parse(readFileSync(fileURLToPath(new URL('../../proto/schemas/ws-client.schema.json', import.meta.url)), 'utf8'));
const messageTypes = schema.oneOf.map((one) => {
  const d = one.$ref ? schema.$defs[one.$ref.split('/').pop()] : one;
  return d.properties.type.const;
});

/** One edit of each type as a co-designer's client sends it (checked against the schema). */
const EXAMPLES = {
  join: { type: 'join', session: 's', token: 't' },
  presence: { type: 'presence', selection: null },
  ping: { type: 'ping' },
  drag: { type: 'drag', target: { vertex: 3 }, position: [0, 0, 1] },
  fold: { type: 'fold', amount: 0.5 },
  drag_end: { type: 'drag_end', target: { vertex: 3 } },
  fold_end: { type: 'fold_end' },
  solve: { type: 'solve', iterations: 50 },
  undo: { type: 'undo' },
  redo: { type: 'redo' },
  reset: { type: 'reset' },
  add_handle: { type: 'add_handle', target: { curve: 'a', index: 2 }, position: [1, 2, 3] },
  remove_handle: { type: 'remove_handle', target: { curve: 'a', index: 2 } },
  set_fixed: { type: 'set_fixed', target: { vertex: 0 }, fixed: true },
  set_solver: { type: 'set_solver', solver: { fairness: 0.01 }, drag_iterations: 10 },
  set_crease: { type: 'set_crease', edge: 4, crease: 'geodesic' },
  set_params: { type: 'set_params', params: { np: 40, h3: 9 } },
  set_units: { type: 'set_units', units: 'cm' },
  draw_crease: { type: 'draw_crease', points: [[0, 0], [50, 80], [100, 100]], curved: true, assignment: 'V', fold_angle: 90 },
  erase_crease: { type: 'erase_crease', crease: 5 },
  relabel_crease: { type: 'relabel_crease', crease: 5, assignment: 'M' },
  reshape_crease: { type: 'reshape_crease', crease: 5, points: [[0, 0], [40, 60], [100, 100]], curved: true },
  rotate_points: { type: 'rotate_points', targets: [{ vertex: 1 }, { vertex: 2 }], axis: [0, 0, 1], angle: 15 },
  add_control_point: { type: 'add_control_point', edge: 2, index: 1 },
  remove_control_point: { type: 'remove_control_point', edge: 2, index: 3 },
  relabel_edge: { type: 'relabel_edge', edges: [6], label: 'S' },
  split_face: { type: 'split_face', face: 1, vertices: [0, 2] },
  merge_faces: { type: 'merge_faces', edge: 7 },
  split_along_ruling: { type: 'split_along_ruling', edge: 2, at: 0.25 },
  split_edge: { type: 'split_edge', edge: 9, at: 0.5 },
  remove_vertex: { type: 'remove_vertex', vertex: 8 },
};

describe('the activity list', () => {
  it('has an example of every message type the protocol has, each one valid', () => {
    expect(Object.keys(EXAMPLES).sort()).toEqual([...messageTypes].sort());
    for (const [type, msg] of Object.entries(EXAMPLES)) expect(validClient(msg), type).toEqual([]);
  });

  it('says in words what every journalled edit did, and nothing for moves shown live', () => {
    for (const type of messageTypes) {
      const text = describeEdit(EXAMPLES[type], { foldAmount: 0.64 });
      if (UNLISTED_MESSAGES.has(type)) {
        expect(text, type).toBe(null);
        continue;
      }
      expect(typeof text, type).toBe('string');
      expect(text.length, type).toBeGreaterThan(4);
      // No field names, no missing values, no protocol codes.
      expect(text, type).not.toMatch(/undefined|NaN|null|\[object|_/);
    }
  });

  it('names crease types, drawn lines and fold amounts as the panels do', () => {
    expect(describeEdit(EXAMPLES.set_crease)).toBe('made edge 4 a geodesic crease');
    expect(describeEdit(EXAMPLES.draw_crease)).toBe('drew a curved valley crease (90°)');
    expect(describeEdit({ type: 'draw_crease', points: [[0, 0], [1, 1]], assignment: 'M' })).toBe('drew a straight mountain crease (180°)');
    expect(describeEdit({ type: 'draw_crease', points: [[0, 0], [1, 1], [2, 0]], curved: true, assignment: 'M' }))
      .toBe('drew a curved mountain crease (90°)');
    expect(describeEdit({ type: 'draw_crease', points: [[0, 0], [1, 1]], assignment: 'C' })).toBe('drew a straight cut');
    expect(describeEdit(EXAMPLES.relabel_crease)).toBe('made crease 5 a mountain crease (180°)');
    expect(describeEdit(EXAMPLES.fold_end, { foldAmount: 0.64 })).toBe('folded the sheet to 64 %');
    expect(describeEdit(EXAMPLES.fold_end)).toBe('moved the fold slider');
    expect(describeEdit(EXAMPLES.relabel_edge)).toBe('made edge 6 curved (S)');
    expect(describeEdit(EXAMPLES.split_along_ruling)).toBe('cut the strips of edge 2 by a ruling at 25 %');
  });
});
