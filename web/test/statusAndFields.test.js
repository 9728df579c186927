// What the editor says about typed numbers and about the last solve (issue 16 item 7: errors that
// name the field; a status line that does not contradict the quality verdict beside it).
import { describe, expect, it } from 'vitest';
import { typedNumberProblem } from '../src/ui/SolverPanel.js';
import { solvedText } from '../src/ui/panels.js';

describe('typedNumberProblem', () => {
  it('takes plain, signed and exponent numbers within the range', () => {
    for (const t of ['0.02', '1', '+3', '.5', '1e-3', '2E2', ' 7 ']) expect(typedNumberProblem(t, { min: 0 })).toBeNull();
  });
  it('refuses what is not a number, not finite, out of range or not whole', () => {
    expect(typedNumberProblem('abc', { min: 0 })).toBe('enter a number');
    expect(typedNumberProblem('', { min: 0 })).toBe('enter a number');
    expect(typedNumberProblem('NaN', {})).toBe('enter a number');
    expect(typedNumberProblem('1,5', {})).toBe('enter a number');
    expect(typedNumberProblem('1e999', { min: 0 })).toBe('enter a finite number');
    expect(typedNumberProblem('-1', { min: 0 })).toBe('at least 0');
    expect(typedNumberProblem('2', { min: 0.05, max: 1 })).toBe('at most 1');
    expect(typedNumberProblem('2.5', { min: 1, max: 100, integer: true })).toBe('enter a whole number');
  });
});

describe('solvedText', () => {
  it('says a release that used its iterations ran them, and names every ending in words', () => {
    expect(solvedText({ reason: 'max_iterations', iterations: 1000 })).toBe('solved: ran its 1000 iterations');
    expect(solvedText({ reason: 'relative_change', iterations: 1 })).toBe('solved: converged after 1 iteration');
    expect(solvedText({ reason: 'diverged', iterations: 3 })).toContain('last good state is kept');
    for (const reason of ['max_iterations', 'residual_tolerance', 'relative_change', 'hard_tolerance', 'time_budget', 'aborted',
      'diverged', 'stalled', 'hard_plateau', 'completed', 'identity_fallback'])
      expect(solvedText({ reason, iterations: 5 })).not.toMatch(/_/);
  });
});
