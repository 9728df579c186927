import { readFileSync } from 'node:fs';
import { fileURLToPath } from 'node:url';
import { describe, expect, it } from 'vitest';
import {
  AddHandleCommand, DragCommand, DragEndCommand, JoinCommand, PingCommand, PresenceCommand, RedoCommand,
  RemoveHandleCommand, ResetCommand, FoldCommand, FoldEndCommand, SetCreaseCommand, SetFixedCommand, SetParamsCommand, SetSolverCommand, SetUnitsCommand, SolveCommand, UndoCommand,
  SOLVER_KEYS, PARAM_KEYS, UNITS, DrawCreaseCommand, EraseCreaseCommand, RelabelCreaseCommand, ReshapeCreaseCommand,
  RotatePointsCommand, AddControlPointCommand, RemoveControlPointCommand,
  RelabelEdgeCommand, SplitFaceCommand, MergeFacesCommand, SplitAlongRulingCommand, SplitEdgeCommand, RemoveVertexCommand,
} from '../src/commands/index.js';
import { PARAM_FIELDS, paramsFor } from '../src/ui/ParamsPanel.js';
import { makeValidator } from './helpers/jsonschema.js';

const schemaDir = fileURLToPath(new URL('../../proto/schemas/', import.meta.url));
const load = (name) => JSON.parse(readFileSync(schemaDir + name, 'utf8'));
const schemas = { 'ws-client.schema.json': load('ws-client.schema.json'), 'scene.schema.json': load('scene.schema.json') };
const validate = makeValidator(schemas);
const validClient = (msg) => validate(JSON.parse(JSON.stringify(msg)), 'ws-client.schema.json');

const t = { curve: 'b', index: 4 };

// Every command the app sends, in the variants it uses.
const cases = [
  ['DragCommand', new DragCommand(t, [1, 2.5, -3])],
  ['DragEndCommand', new DragEndCommand(t)],
  ['DragEndCommand with iterations', new DragEndCommand({ curve: 'a', index: 0 }, 25)],
  ['SolveCommand default', new SolveCommand()],
  ['SolveCommand 100', new SolveCommand(100)],
  ['AddHandleCommand', new AddHandleCommand(t, new Float32Array([1, 2, 3]))],
  ['AddHandleCommand with weight', new AddHandleCommand(t, [1, 2, 3], 2.5)],
  ['RemoveHandleCommand', new RemoveHandleCommand(t)],
  ['SetFixedCommand fix', new SetFixedCommand(t, true)],
  ['SetFixedCommand free', new SetFixedCommand(t, false)],
  ['SetSolverCommand weights', new SetSolverCommand({ fairness: 0.02, fairness_decay: 0.8, regularization: 0.001, unit_normal_weight: 0.1, developability_weight: 1, handle_weight: 3 })],
  ['SetSolverCommand drag settings', new SetSolverCommand({}, { drag_iterations: 2, release_iterations: 20 })],
  ['SetSolverCommand normal spline', new SetSolverCommand({}, { normals: { type: 'spline', degree: 3, points: 12 } })],
  ['SetSolverCommand normal vectors', new SetSolverCommand({}, { normals: { type: 'vectors' } })],
  ['SetSolverCommand one key', new SetSolverCommand({ developability_weight: 2 })],
  ['UndoCommand', new UndoCommand()],
  ['RedoCommand', new RedoCommand()],
  ['ResetCommand', new ResetCommand()],
  ['PresenceCommand selection', new PresenceCommand(t)],
  ['PresenceCommand none + name', new PresenceCommand(null, 'ada')],
  ['JoinCommand', new JoinCommand('8f3c', 'tok', 'ada')],
  ['PingCommand', new PingCommand()],
  // Composite sessions: vertices and S-edge control points, crease types.
  ['DragCommand of a composite vertex', new DragCommand({ vertex: 3 }, [1, 2, 3])],
  ['DragEndCommand of an S-edge control point', new DragEndCommand({ edge: 0, index: 2 })],
  ['SetFixedCommand of a vertex', new SetFixedCommand({ vertex: 0 }, true)],
  ['AddHandleCommand of an S-edge control point', new AddHandleCommand({ edge: 3, index: 1 }, [0, 0, 1])],
  ['PresenceCommand selecting a vertex', new PresenceCommand({ vertex: 2 })],
  ['SetCreaseCommand fold', new SetCreaseCommand(0, 'fold')],
  ['FoldCommand 0', new FoldCommand(0)],
  ['FoldCommand 0.42', new FoldCommand(0.42)],
  ['FoldEndCommand', new FoldEndCommand()],
  ...UNITS.map((u) => [`SetUnitsCommand ${u}`, new SetUnitsCommand(u)]),
  ['SetCreaseCommand none', new SetCreaseCommand(4, 'none')],
  // Composites: turning a group of points (000_… §4.1, Fig. 8).
  ['AddControlPointCommand', new AddControlPointCommand(3, 0)],
  ['RemoveControlPointCommand', new RemoveControlPointCommand(3, 2)],
  ['RelabelEdgeCommand', new RelabelEdgeCommand([3, 7], 'S')],
  ['RelabelEdgeCommand to rulings', new RelabelEdgeCommand([0], 'R')],
  ['SplitFaceCommand', new SplitFaceCommand(2, [4, 9])],
  ['MergeFacesCommand', new MergeFacesCommand(5)],
  ['SplitAlongRulingCommand', new SplitAlongRulingCommand(2, 0.25)],
  ['SplitAlongRulingCommand at the middle', new SplitAlongRulingCommand(0)],
  ['SplitEdgeCommand', new SplitEdgeCommand(4, 0.25)],
  ['RemoveVertexCommand', new RemoveVertexCommand(9)],
  ['RotatePointsCommand', new RotatePointsCommand([{ vertex: 2 }, { vertex: 3 }, { edge: 4, index: 1 }], [0, 0, 1], 20)],
  ['RotatePointsCommand with centre and iterations', new RotatePointsCommand([{ vertex: 0 }], [1, 0, 0], -360, { centre: [0, 100, 0], iterations: 0 })],
  // Strips between two given curves: their curves' control points, and their parameters.
  ['DragCommand of a quasi_strip control point', new DragCommand({ curve: 'c1', index: 5 }, [1, 2, 3])],
  ['DragEndCommand of a conical_strip control point', new DragEndCommand({ curve: 'q', index: 0 })],
  ['SetParamsCommand quasi_strip mapping', new SetParamsCommand('quasi_strip', { mapping: { degree: 3, coefficients: 20 }, samples: 60 })],
  ['SetParamsCommand quasi_strip optimizer', new SetParamsCommand('quasi_strip', { optimizer: 'guided_projection', method: 'discrete', lambda1: 50, lambda2: 2, max_iterations: 300 })],
  ['SetParamsCommand conical_strip', new SetParamsCommand('conical_strip', { np: 30, nq: 34, h3: 1.5, h4: 0.4, ra: 1.3, objective: 'bending_energy', g1: false })],
  // Drawing the crease pattern (composites made from a drawing): listed once the schema has them.
  ...[
    ['DrawCreaseCommand straight', new DrawCreaseCommand([[0, 0], [200, 150]], { assignment: 'M', foldAngle: 60 })],
    ['DrawCreaseCommand curved', new DrawCreaseCommand([[0, 75], [100, 95], [200, 75]], { curved: true, assignment: 'V' })],
    ['EraseCreaseCommand', new EraseCreaseCommand(3)],
    ['RelabelCreaseCommand', new RelabelCreaseCommand(3, 'F')],
    ['ReshapeCreaseCommand', new ReshapeCreaseCommand(3, [[0, 75], [100, 95], [200, 75]], true)],
  ].filter(([, c]) => schemas['ws-client.schema.json'].oneOf.some((r) => r.$ref.endsWith(`/${c.type}`))),
];

describe('commands match ws-client.schema.json', () => {
  it('the validator rejects what the schema rejects', () => {
    expect(validClient({ type: 'drag', op: 1, target: t })).toContain('$.position: is required');
    expect(validClient({ type: 'drag', op: 1, target: t, position: [1, 2] }).length).toBeGreaterThan(0);
    expect(validClient({ type: 'solve', op: 1, iterations: 0 }).length).toBeGreaterThan(0);
    expect(validClient({ type: 'undo', op: 1, extra: true }).length).toBeGreaterThan(0);
    expect(validClient({ type: 'set_fixed', op: 1, target: { curve: 'c', index: 1 }, fixed: true }).length).toBeGreaterThan(0);
    expect(validClient({ type: 'set_solver', op: 1, solver: { fairness: -1 } }).length).toBeGreaterThan(0);
    expect(validClient({ type: 'set_solver', op: 1, solver: { nope: 1 } }).length).toBeGreaterThan(0);
    expect(validClient({ type: 'set_solver', op: 1, solver: {}, normals: { type: 'quaternions' } }).length).toBeGreaterThan(0);
    expect(validClient({ type: 'nope' }).length).toBeGreaterThan(0);
    expect(validClient({ type: 'undo', op: 'x' })).toEqual([]);
  });

  for (const [name, command] of cases) {
    it(`${name} validates, with integer and string op ids`, () => {
      for (const op of [1, 'c-17']) {
        const msg = command.toMessage(op);
        expect(msg.type).toBe(command.type);
        expect(msg.op).toBe(op);
        expect(validClient(msg)).toEqual([]);
      }
      expect(validClient(command.toMessage())).toEqual([]);
    });
  }

  it('covers every message type of the schema', () => {
    const types = schemas['ws-client.schema.json'].oneOf.map((r) => r.$ref.split('/').pop());
    const sent = new Set(cases.map(([, c]) => c.type));
    expect([...sent].sort()).toEqual([...types].sort());
  });

  it('composite targets and crease types are checked before sending', () => {
    expect(() => new AddControlPointCommand(-1, 0)).toThrow(/edge/);
    expect(() => new RelabelEdgeCommand([], 'S')).toThrow(/edges/);
    expect(() => new RelabelEdgeCommand([1], 'X')).toThrow(/label/);
    expect(() => new SplitFaceCommand(0, [1])).toThrow(/vertices/);
    expect(() => new MergeFacesCommand(-2)).toThrow(/edge/);
    expect(() => new SplitAlongRulingCommand(1, 1)).toThrow(/at/);
    expect(() => new SplitAlongRulingCommand(1, 0)).toThrow(/at/);
    expect(() => new SplitAlongRulingCommand(-1)).toThrow(/edge/);
    expect(() => new SplitEdgeCommand(1, 1.5)).toThrow(/at/);
    expect(() => new RemoveVertexCommand(-1)).toThrow(/vertex/);
    expect(validClient({ type: 'split_along_ruling', op: 1, edge: 0, at: 1 }).length).toBeGreaterThan(0);
    expect(new RelabelEdgeCommand([2, 2, 5], 'R').toMessage().edges).toEqual([2, 5]);
    expect(() => new RemoveControlPointCommand(2, 0)).toThrow(/index/);
    expect(new RemoveControlPointCommand(2, 3).toMessage(4)).toEqual({ type: 'remove_control_point', op: 4, edge: 2, index: 3 });
    expect(validClient({ type: 'remove_control_point', op: 1, edge: 0, index: 0 }).length).toBeGreaterThan(0);
    expect(() => new DragCommand({ vertex: -1 }, [0, 0, 0])).toThrow(TypeError);
    expect(() => new DragCommand({ vertex: 1, edge: 2 }, [0, 0, 0])).toThrow(TypeError);
    expect(() => new DragCommand({ edge: 1 }, [0, 0, 0])).toThrow(TypeError);
    expect(() => new SetCreaseCommand(0, 'crumple')).toThrow(TypeError);
    expect(() => new FoldCommand(1.2)).toThrow(TypeError);
    expect(() => new SetUnitsCommand('furlong')).toThrow(TypeError);
    expect(validClient({ type: 'set_units', op: 1, units: 'furlong' }).length).toBeGreaterThan(0);
    expect(() => new FoldCommand(Number.NaN)).toThrow(TypeError);
    expect(new FoldCommand(0.5).toMessage(7)).toEqual({ type: 'fold', op: 7, amount: 0.5 });
    expect(() => new SetCreaseCommand(-1, 'fold')).toThrow(TypeError);
    expect(validClient({ type: 'set_crease', op: 1, edge: 0, crease: 'crumple' }).length).toBeGreaterThan(0);
    expect(validClient({ type: 'drag', op: 1, target: { vertex: 1, curve: 'a' }, position: [0, 0, 0] }).length).toBeGreaterThan(0);
    expect(new SetCreaseCommand(2, 'geodesic').toMessage(5)).toEqual({ type: 'set_crease', op: 5, edge: 2, crease: 'geodesic' });
    expect(new DragCommand({ edge: 0, index: 2 }, [1, 2, 3]).toMessage(6)).toEqual({ type: 'drag', op: 6, target: { edge: 0, index: 2 }, position: [1, 2, 3] });
  });

  it('parameters of strips between curves are checked before sending, naming the field', () => {
    expect(() => new SetParamsCommand('quasi_strip', { np: 3 })).toThrow(/params\.np/);
    expect(() => new SetParamsCommand('conical_strip', { np: 1 })).toThrow(/params\.np/);
    expect(() => new SetParamsCommand('conical_strip', { ra: 0.5 })).toThrow(/params\.ra/);
    expect(() => new SetParamsCommand('quasi_strip', { mapping: { degree: 12 } })).toThrow(/params\.mapping\.degree/);
    expect(() => new SetParamsCommand('quasi_strip', { optimizer: 'newton' })).toThrow(/params\.optimizer/);
    expect(() => new SetParamsCommand('strip', { samples: 3 })).toThrow(/set_params/);
    expect(() => new SetParamsCommand('quasi_strip', {})).toThrow(/params/);
    expect(new SetParamsCommand('quasi_strip', { mapping: { coefficients: 12 } }).toMessage(3))
      .toEqual({ type: 'set_params', op: 3, params: { mapping: { coefficients: 12 } } });
    expect(validClient({ type: 'set_params', op: 1, params: { np: 1 } }).length).toBeGreaterThan(0);
    expect(validClient({ type: 'set_params', op: 1, params: {} }).length).toBeGreaterThan(0);
    expect(validClient({ type: 'set_params', op: 1, params: { colour: 1 } }).length).toBeGreaterThan(0);
    expect(validClient({ type: 'drag', op: 1, target: { curve: 'c3', index: 0 }, position: [0, 0, 0] }).length).toBeGreaterThan(0);
  });

  it('every parameter the panel can set is a field of its scene model and makes a valid message', () => {
    const models = { quasi_strip: 'quasi_strip_model', conical_strip: 'conical_strip_model' };
    for (const [kind, def] of Object.entries(models)) {
      const props = schemas['scene.schema.json'].$defs[def].properties;
      for (const key of PARAM_KEYS[kind]) expect(props).toHaveProperty(key);
      for (const [key, , o] of PARAM_FIELDS[kind]) {
        const value = o.choices ? o.choices[o.choices.length - 1] : o.bool ? true : o.max !== undefined ? o.max : o.min + 1;
        const msg = new SetParamsCommand(kind, paramsFor(key, value)).toMessage(1);
        expect(validClient(msg)).toEqual([]);
      }
    }
  });

  it('builds the exact JSON', () => {
    expect(new DragCommand(t, [1, 2, 3]).toMessage(7)).toEqual({ type: 'drag', op: 7, target: { curve: 'b', index: 4 }, position: [1, 2, 3] });
    expect(new DragEndCommand(t).toMessage(8)).toEqual({ type: 'drag_end', op: 8, target: { curve: 'b', index: 4 } });
    expect(new SolveCommand().toMessage(9)).toEqual({ type: 'solve', op: 9 });
    expect(new SolveCommand(25).toMessage(10)).toEqual({ type: 'solve', op: 10, iterations: 25 });
    expect(new SetFixedCommand(t, true).toMessage(1)).toEqual({ type: 'set_fixed', op: 1, target: t, fixed: true });
    expect(new PresenceCommand(null).toMessage(2)).toEqual({ type: 'presence', op: 2, selection: null });
    expect(new SetSolverCommand({ fairness: 0 }, { drag_iterations: 3 }).toMessage(3)).toEqual({ type: 'set_solver', op: 3, solver: { fairness: 0 }, drag_iterations: 3 });
    expect(new UndoCommand().toMessage(4)).toEqual({ type: 'undo', op: 4 });
    expect(new AddHandleCommand(t, new Float32Array([0.5, 1, 2])).toMessage(5).position).toEqual([0.5, 1, 2]);
  });

  it('every solver key the panel can set is in the scene schema', () => {
    const keys = Object.keys(schemas['scene.schema.json'].$defs.solver.properties);
    expect([...SOLVER_KEYS].sort()).toEqual([...keys].sort());
  });

  it('rejects malformed arguments early', () => {
    expect(() => new DragCommand({ curve: 'c', index: 0 }, [0, 0, 0])).toThrow();
    expect(() => new DragCommand(t, [0, NaN, 0])).toThrow();
    expect(() => new SolveCommand(0)).toThrow();
    expect(() => new SetSolverCommand({ bogus: 1 })).toThrow();
    expect(() => new AddHandleCommand(t, [0, 0, 0], 0)).toThrow();
  });
});
