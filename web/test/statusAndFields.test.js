// What the editor says about typed numbers and about the last solve (issue 16 item 7: errors that
// name the field; a status line that does not contradict the quality verdict beside it).
import { describe, expect, it } from 'vitest';
import { typedNumberProblem } from '../src/ui/SolverPanel.js';
import { solvedText } from '../src/ui/panels.js';
import { formatExponential, formatFixed, formatNumber, formatSignificant } from '../src/ui/dom.js';
import { percent, significant } from '../src/ui/QuadMeshControls.js';
import { boardControlStates } from '../src/ui/CreaseBoardPanel.js';

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

describe('numbers shown for metrics', () => {
  it('show denormals and other negligible magnitudes as 0', () => {
    for (const tiny of [6.3e-321, 4e-317, -4e-317, 1e-301, 5e-324, -0]) {
      expect(formatNumber(tiny)).toBe('0');
      expect(formatExponential(tiny, 1)).toBe('0');
      expect(formatSignificant(tiny)).toBe('0');
      expect(percent(tiny)).toBe('0 %');
      expect(significant(tiny)).toBe('0');
    }
  });

  it('keep small values that are measurements', () => {
    expect(formatExponential(6.3e-21, 1)).toBe('6.3e-21');
    expect(formatNumber(1.5e-9)).toBe('1.50e-9');
    expect(formatNumber(0.25)).toBe('0.250');
    expect(formatSignificant(0.093149, 2)).toBe('0.093');
    expect(percent(1e-9)).toBe('1.00e-7 %');
    expect(significant(2e-200)).toBe('2.00e-200');
  });

  it('write a value that rounds to zero without a minus sign', () => {
    expect(formatFixed(-1e-5, 3)).toBe('0.000');
    expect(formatFixed(-0.04, 1)).toBe('0.0');
    expect(formatFixed(-0.06, 1)).toBe('-0.1');
    expect(formatFixed(12.3456, 2)).toBe('12.35');
    expect(formatNumber(-0.0100001, 3)).toBe('-0.010');
  });
});

describe('the crease board toolbar', () => {
  it('is off for a view-only editor, with or without a crease selected', () => {
    for (const crease of [false, true]) {
      const off = boardControlStates({ editable: false, crease, outline: false, assignment: 'V' });
      expect(off).toEqual({ assignmentDisabled: true, angleDisabled: true, editsDisabled: true });
    }
  });

  it('is on for an editor, the angle only for mountain and valley creases, nothing for the outline', () => {
    expect(boardControlStates({ editable: true, crease: false, outline: false, assignment: 'V' }))
      .toEqual({ assignmentDisabled: false, angleDisabled: false, editsDisabled: true });
    expect(boardControlStates({ editable: true, crease: true, outline: false, assignment: 'F' }))
      .toEqual({ assignmentDisabled: false, angleDisabled: true, editsDisabled: false });
    expect(boardControlStates({ editable: true, crease: false, outline: true, assignment: 'V' }))
      .toEqual({ assignmentDisabled: true, angleDisabled: true, editsDisabled: true });
  });
});
