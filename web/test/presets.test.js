// The start page's cards show a scene's summary: every shipped example has one a newcomer can read
// (discovered from ../examples, so a new example is held to it too), and a scene without one shows
// the first sentence of its description.
import fs from 'node:fs';
import path from 'node:path';
import { describe, expect, it } from 'vitest';
import { PRESETS, sceneSummary } from '../src/presets.js';

const examples = path.resolve(__dirname, '..', '..', 'examples');
const files = fs.readdirSync(examples).filter((f) => f.endsWith('.json'));

describe('example summaries', () => {
  it('every example is a preset and carries a summary of one short sentence without references', () => {
    expect(PRESETS.map((p) => p.file).sort()).toEqual(files.slice().sort());
    for (const file of files) {
      const scene = JSON.parse(fs.readFileSync(path.join(examples, file), 'utf8'));
      const summary = scene.summary;
      expect(typeof summary, file).toBe('string');
      expect(summary.length, `${file}: ${summary}`).toBeLessThanOrEqual(100);
      expect(summary, file).toMatch(/^[A-Z].*[.]$/);
      expect(summary.slice(0, -1), `${file}: one sentence`).not.toMatch(/[.!?]\s/);
      for (const jargon of [/\beq\./i, /\bfig\./i, /§/, /\bissue\b/i, /et al\./, /\bM′/, /[A-Z]\d/]) {
        expect(summary, `${file}: ${jargon}`).not.toMatch(jargon);
      }
      expect(PRESETS.find((p) => p.file === file).summary).toBe(summary);
    }
  });

  it('a scene without a summary shows the first sentence of its description', () => {
    expect(sceneSummary({ description: 'A flat sheet. It bends (eq. 7).' })).toBe('A flat sheet.');
    expect(sceneSummary({ description: 'Radius 2.5 cm and 3.1 cm, no full stop' })).toBe('Radius 2.5 cm and 3.1 cm, no full stop');
    expect(sceneSummary({ summary: '  Own words.  ', description: 'Ignored. Really.' })).toBe('Own words.');
    expect(sceneSummary({})).toBe('');
  });
});
