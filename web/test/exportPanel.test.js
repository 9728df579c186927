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

describe('print size note', () => {
  it('says when the flat patterns would print tiny or huge at true size, naming the size', async () => {
    const { printSizeNote } = await import('../src/ui/panels.js');
    // The curved-fold demo: 2 × 2 units, a diagonal of 2.83, in mm.
    expect(printSizeNote(2.83, 'mm')).toMatch(/^At 1 unit = 1 mm this design is 2\.8 mm across/);
    expect(printSizeNote(1.5, 'cm')).toMatch(/1 cm this design is 15 mm across/);
    expect(printSizeNote(2.83, 'cm')).toBeNull();  // 28 mm
    expect(printSizeNote(2.83, 'in')).toBeNull();  // 72 mm
    expect(printSizeNote(250, 'mm')).toBeNull();
    expect(printSizeNote(3, 'm')).toMatch(/3 m across/);
    expect(printSizeNote(0, 'mm')).toBeNull();
    expect(printSizeNote(undefined, 'mm')).toBeNull();
  });
});
