// Which composites export their flat pieces (issue 15): those cut apart along seams, as the server
// decides (SceneSolver::cutAlongSeams) — checked on the shipped presets.
import fs from 'node:fs';
import path from 'node:path';
import { describe, expect, it } from 'vitest';
import { cutAlongSeams } from '../src/ui/panels.js';

const examples = path.resolve(__dirname, '..', '..', 'examples');
const model = (name) => JSON.parse(fs.readFileSync(path.join(examples, name), 'utf8')).model;

describe('cutAlongSeams', () => {
  it('holds for the bunny cover and for no composite preset with a development', () => {
    expect(cutAlongSeams(model('composite-cover-bunny.json'))).toBe(true);
    const sheets = fs.readdirSync(examples).filter((f) => f.startsWith('composite-') && f !== 'composite-cover-bunny.json');
    expect(sheets.length).toBeGreaterThan(3);
    for (const f of sheets) expect(cutAlongSeams(model(f))).toBe(false);
  });

  it('needs a seam: without a development, folds alone are not pieces', () => {
    const m = model('composite-two-creases.json');
    delete m.development;
    expect(cutAlongSeams(m)).toBe(false);
    const cover = model('composite-cover-bunny.json');
    for (const e of cover.edges) if (e.type === 'S') e.crease = 'fold';
    expect(cutAlongSeams(cover)).toBe(false);
    expect(cutAlongSeams(null)).toBe(false);
  });
});
