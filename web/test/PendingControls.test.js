import { describe, expect, it } from 'vitest';
import { PendingControls } from '../src/ui/PendingControls.js';

/** A stand-in for a lil-gui controller: only its element's class list matters here. */
function controller() {
  const classes = new Set();
  return { domElement: { classList: { add: (c) => classes.add(c), remove: (c) => classes.delete(c) } }, classes };
}

describe('PendingControls', () => {
  it('keeps a control pending until the last of its commands is settled', () => {
    const c = controller();
    const p = new PendingControls('set_solver', 'solver:', (key) => (key === 'fairness' ? c : undefined));
    p.sent('fairness');
    p.sent('fairness');
    expect(p.has('fairness')).toBe(true);
    expect(c.classes.has('pending')).toBe(true);
    const command = { type: 'set_solver', source: 'solver:fairness' };
    expect(p.settled(command)).toBe('fairness');
    expect(c.classes.has('pending')).toBe(true);
    expect(p.settled(command)).toBe('fairness');
    expect(p.has('fairness')).toBe(false);
    expect(c.classes.has('pending')).toBe(false);
  });

  it('ignores commands of another type or source and keys without a controller', () => {
    const p = new PendingControls('set_params', 'params:', () => undefined);
    expect(p.settled(null)).toBe(null);
    expect(p.settled({ type: 'set_solver', source: 'params:samples' })).toBe(null);
    expect(p.settled({ type: 'set_params', source: 'viewport' })).toBe(null);
    p.sent('samples');
    expect(p.settled({ type: 'set_params', source: 'params:samples' })).toBe('samples');
    expect(p.has('samples')).toBe(false);
    p.sent('samples');
    p.clear();
    expect(p.has('samples')).toBe(false);
  });
});
