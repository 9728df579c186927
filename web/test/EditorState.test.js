import { describe, expect, it } from 'vitest';
import { EditorState, RESIDUAL_HISTORY_LIMIT } from '../src/state/EditorState.js';
import { DragCommand, FoldCommand, FoldEndCommand, SetSolverCommand } from '../src/commands/index.js';
import { nothingToFold, sessionFoldAmount } from '../src/ui/FoldPanel.js';
import { MAX_DECADES, decadeRange, decadeSplits } from '../src/ui/logScale.js';

describe('EditorState', () => {
  it('signals changes with on/emit and can unsubscribe', () => {
    const s = new EditorState();
    const seen = [];
    const off = s.on('selection', (sel) => seen.push(sel));
    const changes = [];
    s.on('change', ({ event }) => changes.push(event));
    expect(s.setSelection({ curve: 'a', index: 1 })).toBe(true);
    expect(s.setSelection({ curve: 'a', index: 1 })).toBe(false);
    off();
    s.setSelection(null);
    expect(seen).toEqual([{ curve: 'a', index: 1 }]);
    expect(changes).toEqual(['selection', 'selection']);
  });

  it('can edit only with an edit link while connected, and signals each change of that', () => {
    const s = new EditorState();
    const seen = [];
    s.on('editable', (v) => seen.push(v));
    s.setConnection('connecting');
    s.applyState({ type: 'state', session: 'x', role: 'edit', seq: 1, scene: { model: { kind: 'strip' } } });
    expect(s.canEdit).toBe(false);  // the join is answered before the connection counts as up
    s.setConnection('connected');
    expect(s.canEdit).toBe(true);
    s.setConnection('reconnecting');
    expect(s.canEdit).toBe(false);
    s.setConnection('connecting');
    s.setConnection('offline');
    s.setConnection('connected');
    s.applyState({ type: 'state', session: 'x', role: 'edit', seq: 2, scene: { model: { kind: 'strip' } } });  // a resync
    expect(seen).toEqual([true, false, true]);
    s.applyState({ type: 'state', session: 'x', role: 'view', seq: 2, scene: { model: { kind: 'strip' } } });
    expect(s.canEdit).toBe(false);
    expect(seen).toEqual([true, false, true, false]);
  });

  it('shows the quality verdict of the state it shows: an undo\'s update replaces the last solve\'s', () => {
    const s = new EditorState();
    s.applyState({ type: 'state', session: 'x', role: 'edit', seq: 1, scene: { model: { kind: 'composite' } } });
    const miss = { met: false, checks: [{ metric: 'fold_angle_error_max_deg', value: 77.5, limit: 9.1, ok: false }] };
    s.applySolved({ type: 'solved', seq: 2, reason: 'max_iterations', iterations: 1000, quality: miss, metrics: {} });
    expect(s.quality).toEqual(miss);
    const met = { met: true, checks: [{ metric: 'fold_angle_error_max_deg', value: 3.5e-7, limit: 9.1, ok: true }] };
    s.applyUpdate({ type: 'update', seq: 3, scene: { model: { kind: 'composite' } }, metrics: {}, quality: met, undo: { available: 1, redo_available: 1 } });
    expect(s.quality).toEqual(met);
    expect(s.lastSolved.reason).toBe('max_iterations');  // how the last solve ended is still its own
  });

  it('has nothing to fold on a flat design without targets, and says what to do instead', () => {
    const blank = { model: { kind: 'composite', drawing: { strokes: [] }, edges: [], faces: [] } };
    expect(nothingToFold(blank, 0)).toMatch(/draw a mountain or valley crease/);
    expect(nothingToFold({ model: { kind: 'composite', edges: [] } }, 0.2)).toMatch(/Drag a point/);
    expect(nothingToFold({ model: { ...blank.model, fold_angles: [{ edge: 1, angle: 90 }] } }, 0)).toBe(null);
    expect(nothingToFold(blank, 12)).toBe(null);  // a drag folded it: the first move takes that as 100 %
    expect(nothingToFold({ model: { kind: 'strip' } }, 0)).toBe(null);
  });

  it('keeps a bounded per-term residual history with gaps for zero terms', () => {
    const s = new EditorState();
    s.applyIterate({ type: 'iterate', seq: 1, iteration: 1, residuals: { developability: 1 }, metrics: {} });
    s.applyIterate({ type: 'iterate', seq: 1, iteration: 2, residuals: { developability: 0.5, handle: 0 }, metrics: {} });
    expect(s.residualHistory.x).toEqual([1, 2]);
    expect(s.residualHistory.terms.developability).toEqual([1, 0.5]);
    expect(s.residualHistory.terms.handle).toEqual([null, null]);
    for (let i = 0; i < RESIDUAL_HISTORY_LIMIT + 10; i++) s.applyIterate({ type: 'iterate', seq: 1, iteration: i, residuals: { developability: 1 }, metrics: {} });
    expect(s.residualHistory.x.length).toBe(RESIDUAL_HISTORY_LIMIT);
    expect(s.residualHistory.terms.handle.length).toBe(RESIDUAL_HISTORY_LIMIT);
    expect(s.iterateCount).toBe(RESIDUAL_HISTORY_LIMIT + 12);
  });

  it('takes the amount of an applied fold as the session\'s: the fold\'s iterates carry no fold_amount', () => {
    const s = new EditorState();
    s.applyState({ type: 'state', session: 'x', role: 'edit', seq: 1, scene: { model: { kind: 'composite', fold_amount: 0 } }, metrics: { fold_amount: 0 } });
    const shown = [];
    s.on('metrics', (m) => shown.push(sessionFoldAmount(m, s.scene)));
    s.applyAck({ type: 'ack', op: 1, seq: 2 }, new FoldCommand(0.4));
    s.applyIterate({ type: 'iterate', seq: 2, iteration: 1, residuals: {}, metrics: { face_flatness_max: 1e-9 } });
    expect(s.metrics.fold_amount).toBe(0.4);
    s.applyAck({ type: 'ack', op: 2, seq: 3 }, new FoldCommand(0.94));
    s.applyIterate({ type: 'iterate', seq: 3, iteration: 1, residuals: {}, metrics: { face_flatness_max: 1e-9 } });
    s.applyAck({ type: 'ack', op: 3, seq: 4 }, new FoldEndCommand());
    expect(sessionFoldAmount(s.metrics, s.scene)).toBe(0.94);
    // A collaborator's fold, then the solved release (its metrics have the settled amount).
    s.applyEdit({ type: 'edit', seq: 5, by: 2, edit: { type: 'fold', amount: 0.3 } });
    expect(s.metrics.fold_amount).toBe(0.3);
    s.applySolved({ type: 'solved', seq: 6, reason: 'max_iterations', iterations: 5, metrics: { fold_amount: 0.3 } });
    expect(shown.filter((a) => a === 0)).toEqual([]);
    expect(shown).toEqual([0.4, 0.4, 0.94, 0.94, 0.3, 0.3]);
  });

  it('notes the undo step a drag starts (drags send no update)', () => {
    const s = new EditorState();
    s.applyUpdate({ type: 'update', seq: 2, undo: { available: 0, redo_available: 2 } });
    s.applyAck({ type: 'ack', op: 1, seq: 3 }, new DragCommand({ curve: 'b', index: 0 }, [0, 0, 0]));
    expect(s.undo).toEqual({ available: 1, redo_available: 0 });
    s.applyEdit({ type: 'edit', seq: 4, by: 2, edit: { type: 'drag' } });
    expect(s.undo).toEqual({ available: 1, redo_available: 0 });
  });

  it('notes the undo step a fold gesture starts, and takes the exact counts from solved', () => {
    const s = new EditorState();
    s.applyEdit({ type: 'edit', seq: 4, by: 2, edit: { type: 'fold', amount: 0.5 } });
    expect(s.undo).toEqual({ available: 1, redo_available: 0 });
    const seen = [];
    s.on('undo', (u) => seen.push(u));
    s.applyServerMessage({ type: 'solved', seq: 6, reason: 'max_iterations', iterations: 3, metrics: {}, undo: { available: 3, redo_available: 0 } });
    expect(s.undo).toEqual({ available: 3, redo_available: 0 });
    expect(seen).toEqual([{ available: 3, redo_available: 0 }]);
    s.applyServerMessage({ type: 'solved', seq: 7, reason: 'max_iterations', iterations: 3, metrics: {} });  // an older server
    expect(s.undo).toEqual({ available: 3, redo_available: 0 });
  });

  it('takes the drag settings from acked and others\' set_solver edits', () => {
    const s = new EditorState();
    s.applyAck({ type: 'ack', op: 1, seq: 1 }, new SetSolverCommand({}, { drag_iterations: 3 }));
    expect(s.settings.drag_iterations).toBe(3);
    s.applyEdit({ type: 'edit', seq: 2, by: 5, edit: { type: 'set_solver', solver: {}, release_iterations: 40 } });
    expect(s.settings).toEqual({ drag_iterations: 3, release_iterations: 40 });
  });
});

describe('residual plot log scale', () => {
  it('spans whole decades around the data', () => {
    expect(decadeRange([[0.5, null, 2e-7], [0, 3]])).toEqual([1e-7, 10]);
    expect(decadeRange([[null, 0]])).toEqual([1e-12, 1]);
    expect(decadeRange([[1]])).toEqual([1, 10]);
  });
  it('shows at most MAX_DECADES below the largest value, whatever reached rounding level', () => {
    expect(decadeRange([[3e-203, 0.4], [2e-5]])).toEqual([Math.pow(10, -MAX_DECADES), 1]);
    expect(decadeRange([[5e-300, 2e-290]])).toEqual([1e-300, 1e-289]);
  });
  it('thins decade ticks', () => {
    expect(decadeSplits(1e-6, 1, 10).length).toBe(7);
    expect(decadeSplits(1e-30, 1, 6).length).toBeLessThanOrEqual(6);
    expect(decadeSplits(1e-30, 1, 6).at(-1)).toBe(1);
  });
});
