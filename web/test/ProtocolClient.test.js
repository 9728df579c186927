import { beforeEach, describe, expect, it } from 'vitest';
import { ProtocolClient, backoffDelay, openEarlyJoin, sessionSocketUrl } from '../src/net/ProtocolClient.js';
import { EditorState } from '../src/state/EditorState.js';
import { DragCommand, PresenceCommand, SetSolverCommand, SolveCommand, UndoCommand } from '../src/commands/index.js';

// A fake WebSocket: records what the client sends; the test plays the server.
class FakeSocket {
  static instances = [];
  constructor(url) {
    this.url = url;
    this.readyState = 0;
    this.sent = [];
    FakeSocket.instances.push(this);
  }
  send(text) {
    if (this.readyState !== 1) throw new Error('not open');
    this.sent.push(JSON.parse(text));
  }
  close(code = 1000) {
    if (this.readyState === 3) return;
    this.readyState = 3;
    this.onclose && this.onclose({ code });
  }
  // server side
  open() {
    this.readyState = 1;
    this.onopen && this.onopen({});
  }
  receive(msg) {
    this.onmessage && this.onmessage({ data: JSON.stringify(msg) });
  }
  drop(code = 1006) {
    this.readyState = 3;
    this.onclose && this.onclose({ code });
  }
}

// Manual timers: run them explicitly and check their delays.
class FakeTimers {
  constructor() {
    this.queue = [];
    this.nextId = 1;
  }
  setTimeout = (fn, ms) => {
    const id = this.nextId++;
    this.queue.push({ id, fn, ms });
    return id;
  };
  clearTimeout = (id) => {
    this.queue = this.queue.filter((t) => t.id !== id);
  };
  runNext() {
    const t = this.queue.shift();
    if (!t) throw new Error('no timer pending');
    t.fn();
    return t.ms;
  }
}

const stateMessage = (seq = 3) => ({
  type: 'state', session: 's1', seq, you: 7, role: 'edit',
  scene: { format: 'devsurf-scene', version: 1, model: { kind: 'strip', a: { degree: 1, points: [] }, b: { degree: 1, points: [] } }, solver: { fairness: 0.01 } },
  metrics: { warp_angle_max_deg: 4.5 }, constraints: { fixed: [{ curve: 'a', index: 0 }], handles: [] },
  participants: [{ id: 7, name: 'ada', color: '#e6194b', role: 'edit', selection: null, dragging: null }],
  settings: { drag_iterations: 1, release_iterations: 10 }, undo: { available: 0, redo_available: 0 },
});

let state, timers, client;
const socket = () => FakeSocket.instances[FakeSocket.instances.length - 1];

function joinedClient() {
  client.connect('s1', 'edit-token', 'ada');
  socket().open();
  socket().receive(stateMessage());
  return socket();
}

beforeEach(() => {
  FakeSocket.instances = [];
  state = new EditorState();
  timers = new FakeTimers();
  client = new ProtocolClient({ url: 'ws://test/ws', state, WebSocketImpl: FakeSocket, timers });
});

describe('ProtocolClient', () => {
  it('joins on open and becomes connected on the state message', () => {
    const connections = [];
    state.on('connection', ({ connection }) => connections.push(connection));
    client.connect('s1', 'edit-token', 'ada');
    expect(state.connection).toBe('connecting');
    const ws = socket();
    expect(ws.url).toBe('ws://test/ws?session=s1');  // the session in the URL: a proxy routes by it
    ws.open();
    expect(ws.sent).toEqual([{ type: 'join', session: 's1', token: 'edit-token', name: 'ada' }]);
    expect(state.connection).toBe('connecting');
    ws.receive(stateMessage(3));
    expect(state.connection).toBe('connected');
    expect(state.session).toBe('s1');
    expect(state.role).toBe('edit');
    expect(state.seq).toBe(3);
    expect(state.you).toBe(7);
    expect(state.participants).toHaveLength(1);
    expect(state.constraints.fixed).toEqual([{ curve: 'a', index: 0 }]);
    expect(connections).toEqual(['connecting', 'connected']);
  });

  it('sends no edits from a view-only link: each is refused locally as forbidden, presence still goes', () => {
    client.connect('s1', 'view-token', 'bob');
    const ws = socket();
    ws.open();
    ws.receive({ ...stateMessage(3), role: 'view' });
    expect(state.role).toBe('view');
    const before = ws.sent.length;
    for (const command of [new UndoCommand(), new SolveCommand(), new SetSolverCommand({ fairness: 0.1 }),
      new DragCommand({ curve: 'a', index: 0 }, [0, 0, 1])]) {
      expect(client.send(command)).toBeNull();
      expect(state.lastError.code).toBe('forbidden');
      expect(state.lastError.message).toMatch(/view only/);
    }
    expect(ws.sent.length).toBe(before);
    expect(client.send(new PresenceCommand({ curve: 'a', index: 0 }, 'bob'))).not.toBeNull();
    expect(ws.sent.at(-1).type).toBe('presence');
  });

  it('joins on a socket the page opened early: at once when open, on open when still connecting', () => {
    const early = new FakeSocket('ws://test/ws');
    early.readyState = 1;
    client.connect('s1', 'edit-token', 'ada', early);
    expect(FakeSocket.instances).toHaveLength(1);
    expect(early.sent).toEqual([{ type: 'join', session: 's1', token: 'edit-token', name: 'ada' }]);
    early.receive(stateMessage(3));
    expect(state.connection).toBe('connected');

    FakeSocket.instances = [];
    const connecting = new FakeSocket('ws://test/ws');
    const other = new ProtocolClient({ url: 'ws://test/ws', state: new EditorState(), WebSocketImpl: FakeSocket, timers });
    other.connect('s1', 'edit-token', 'ada', connecting);
    expect(connecting.sent).toEqual([]);
    connecting.open();
    expect(connecting.sent).toHaveLength(1);
    expect(FakeSocket.instances).toHaveLength(1);
  });

  it('takes over an early join: one join, and the answers that came before it applied in order', () => {
    const early = openEarlyJoin('ws://test/ws', 's1', 'edit-token', 'ada', FakeSocket);
    const ws = early.socket;
    ws.open();
    expect(ws.sent).toEqual([{ type: 'join', session: 's1', token: 'edit-token', name: 'ada' }]);
    ws.receive(stateMessage(3));
    ws.receive({ type: 'error', code: 'invalid', message: 'drag: no such point', path: 'target' });
    expect(state.connection).toBe('offline');  // nothing applied before the client takes over
    client.connect('s1', 'edit-token', 'ada', early);
    expect(FakeSocket.instances).toHaveLength(1);
    expect(ws.sent).toHaveLength(1);
    expect(state.connection).toBe('connected');
    expect(state.seq).toBe(3);
    expect(state.lastError && state.lastError.message).toMatch(/no such point/);
    ws.receive({ ...stateMessage(4), type: 'state' });
    expect(state.seq).toBe(4);
  });

  it('joins itself on an early join whose socket was still connecting', () => {
    const early = openEarlyJoin('ws://test/ws', 's1', 'edit-token', 'ada', FakeSocket);
    client.connect('s1', 'edit-token', 'ada', early);
    expect(FakeSocket.instances).toHaveLength(1);
    early.socket.open();
    expect(early.socket.sent).toEqual([{ type: 'join', session: 's1', token: 'edit-token', name: 'ada' }]);
    early.socket.receive(stateMessage(2));
    expect(state.connection).toBe('connected');
  });

  it('opens a socket of its own when the early one has closed already', () => {
    const closed = new FakeSocket('ws://test/ws');
    closed.readyState = 3;
    client.connect('s1', 'edit-token', 'ada', closed);
    expect(FakeSocket.instances).toHaveLength(2);
    socket().open();
    expect(socket().sent).toHaveLength(1);
    expect(closed.sent).toEqual([]);
  });

  it('gives every command an increasing op id and matches acks by op', () => {
    const ws = joinedClient();
    const acks = [];
    state.on('ack', ({ message, command }) => acks.push([message.op, command && command.type]));
    const op1 = client.send(new SolveCommand(5));
    const op2 = client.send(new UndoCommand());
    expect(op2).toBeGreaterThan(op1);
    expect(ws.sent.slice(1)).toEqual([
      { type: 'solve', op: op1, iterations: 5 },
      { type: 'undo', op: op2 },
    ]);
    expect(client.pending.size).toBe(2);
    // Acks may come in any order.
    ws.receive({ type: 'ack', op: op2, seq: 5 });
    ws.receive({ type: 'ack', op: op1, seq: 4 });
    expect(acks).toEqual([[op2, 'undo'], [op1, 'solve']]);
    expect(client.pending.size).toBe(0);
    expect(state.seq).toBe(5);
  });

  it('matches errors to their command by op', () => {
    const ws = joinedClient();
    const errors = [];
    state.on('error', (e) => errors.push(e));
    const cmd = new SetSolverCommand({ fairness: -1 }, {}, { source: 'solver:fairness' });
    const op = client.send(cmd);
    client.send(new SolveCommand());
    ws.receive({ type: 'error', op, code: 'invalid', message: 'solver.fairness: must be ≥ 0, got -1', path: 'solver.fairness' });
    expect(errors).toHaveLength(1);
    expect(errors[0].command).toBe(cmd);
    expect(errors[0].command.source).toBe('solver:fairness');
    expect(state.lastError.code).toBe('invalid');
    expect(client.pending.size).toBe(1);
    // An error without op (or with an unknown one) is still reported, without a command.
    ws.receive({ type: 'error', code: 'rate_limited', message: 'slow down' });
    expect(errors[1].command).toBeNull();
    expect(state.lastError.message).toBe('slow down');
  });

  it('refuses to send while not connected and says so', () => {
    const errors = [];
    state.on('error', (e) => errors.push(e));
    client.connect('s1', 'edit-token');
    expect(client.send(new SolveCommand())).toBeNull();
    expect(errors[0].message.code).toBe('offline');
  });

  it('reconnects with exponential back-off 250 ms → 8 s', () => {
    expect([0, 1, 2, 3, 4, 5, 6, 10].map((a) => backoffDelay(a))).toEqual([250, 500, 1000, 2000, 4000, 8000, 8000, 8000]);
    joinedClient();
    socket().drop();
    expect(state.connection).toBe('reconnecting');
    const delays = [];
    for (let i = 0; i < 8; i++) {
      const before = FakeSocket.instances.length;
      delays.push(timers.runNext());
      expect(FakeSocket.instances.length).toBe(before + 1);
      // The server is still down: the new socket fails without opening.
      socket().drop();
    }
    expect(delays).toEqual([250, 500, 1000, 2000, 4000, 8000, 8000, 8000]);
    expect(client.scheduledDelays.slice(0, 8)).toEqual(delays);
    expect(state.connection).toBe('reconnecting');
  });

  it('resyncs on reconnect: re-joins and takes the fresh state; back-off restarts', () => {
    let ws = joinedClient();
    const op = client.send(new SolveCommand());
    const errors = [];
    state.on('error', (e) => errors.push(e));
    ws.drop();
    // The pending solve's outcome is unknown: it fails locally.
    expect(errors).toHaveLength(1);
    expect(errors[0].message.code).toBe('disconnected');
    expect(errors[0].command.type).toBe('solve');
    expect(client.pending.has(op)).toBe(false);

    expect(timers.runNext()).toBe(250);
    ws = socket();
    ws.open();
    expect(ws.sent).toEqual([{ type: 'join', session: 's1', token: 'edit-token', name: 'ada' }]);
    expect(state.connection).toBe('reconnecting');
    const resynced = [];
    state.on('session', (m) => resynced.push(m.seq));
    ws.receive(stateMessage(42));
    expect(resynced).toEqual([42]);
    expect(state.seq).toBe(42);
    expect(state.connection).toBe('connected');
    // Dropping again starts from 250 ms.
    ws.drop();
    expect(timers.runNext()).toBe(250);
  });

  it('drags lost in a drop are not reported', () => {
    const ws = joinedClient();
    const errors = [];
    state.on('error', (e) => errors.push(e));
    client.send(new DragCommand({ curve: 'b', index: 1 }, [0, 0, 0]));
    ws.drop();
    expect(errors).toHaveLength(0);
  });

  for (const code of ['unauthorized', 'quarantined']) {
    it(`stops for good after ${code}`, () => {
      client.connect('s1', 'bad');
      const ws = socket();
      ws.open();
      ws.receive({ type: 'error', code, message: 'no' });
      ws.drop(1008);
      expect(state.connection).toBe('offline');
      expect(state.lastError.code).toBe(code);
      expect(timers.queue).toHaveLength(0);
    });
  }

  it('close() goes offline without reconnecting', () => {
    const ws = joinedClient();
    client.close();
    expect(state.connection).toBe('offline');
    expect(ws.readyState).toBe(3);
    expect(timers.queue).toHaveLength(0);
  });

  it('routes the other server messages into the editor state', () => {
    const ws = joinedClient();
    ws.receive({ type: 'presence', participants: [{ id: 7 }, { id: 8, name: 'bob', selection: { curve: 'a', index: 2 } }] });
    expect(state.participants.map((p) => p.id)).toEqual([7, 8]);
    ws.receive({ type: 'iterate', seq: 9, iteration: 1, residuals: { developability: 0.5, fairness: 0 }, metrics: { warp_angle_max_deg: 2 }, time_ms: 1.5 });
    expect(state.seq).toBe(9);
    expect(state.metrics.warp_angle_max_deg).toBe(2);
    expect(state.lastIterate.iteration).toBe(1);
    expect(state.iterateCount).toBe(1);
    expect(state.residualHistory.terms.developability).toEqual([0.5]);
    expect(state.residualHistory.terms.fairness).toEqual([null]);
    ws.receive({ type: 'solved', seq: 9, reason: 'max_iterations', iterations: 10, metrics: { warp_angle_max_deg: 1 } });
    expect(state.lastSolved.reason).toBe('max_iterations');
    ws.receive({ type: 'update', seq: 10, undo: { available: 1, redo_available: 0 }, scene: { model: { fixed: [], handles: [{ curve: 'b', index: 1, position: [0, 0, 0] }] } } });
    expect(state.undo.available).toBe(1);
    expect(state.constraints.handles).toHaveLength(1);
    expect(state.seq).toBe(10);
  });
});

describe('sessionSocketUrl', () => {
  it('names the session in the socket URL, encoded, so a proxy can route by it', () => {
    expect(sessionSocketUrl('ws://h/ws', 'demo-strip')).toBe('ws://h/ws?session=demo-strip');
    expect(sessionSocketUrl('ws://h/ws?x=1', 'a b&c')).toBe('ws://h/ws?x=1&session=a%20b%26c');
    expect(sessionSocketUrl('ws://h/ws', '')).toBe('ws://h/ws');
  });
});

describe('a session moving between daemons', () => {
  it('treats an `unavailable` join answer as a move: no error shown, a reconnect that says so and joins', () => {
    const errors = [];
    state.on('error', (e) => errors.push(e));
    const connections = [];
    state.on('connection', (c) => connections.push(c));
    client.connect('s1', 'edit-token', 'ada');
    const first = socket();
    first.open();
    first.receive({ type: 'error', code: 'unavailable', message: 'served by node2', path: 'session' });
    first.drop(1013);
    expect(errors).toEqual([]);
    expect(client.fatal).toBe(null);
    const last = connections[connections.length - 1];
    expect(last.connection).toBe('reconnecting');
    expect(last.detail.moving).toBe(true);
    timers.runNext();  // the back-off
    const second = socket();
    expect(second).not.toBe(first);
    expect(second.url).toBe('ws://test/ws?session=s1');
    second.open();
    second.receive(stateMessage());
    expect(state.connection).toBe('connected');
  });
});
